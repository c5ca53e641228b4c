"""A local live video stream for tests: MPEG-TS over HTTP, encoded by PyAV as it is sent.

Like a network camera, the server encodes each frame when it sends it, paced at a frame rate,
with no length announced; the reader sees frames arrive over time.
"""

from __future__ import annotations

import contextlib
import http.server
import threading
import time
from collections.abc import Iterator, Sequence
from fractions import Fraction

import av
import numpy as np
from numpy.typing import NDArray


class StreamServer:
    """Serve `frames` as ``http://127.0.0.1:PORT/live.ts``; ``sent`` counts frames written."""

    def __init__(self, frames: Sequence[NDArray[np.uint8]], pace: float) -> None:
        self.frames = frames
        self.pace = pace
        self.sent = 0
        self.done = threading.Event()
        server = self

        class Handler(http.server.BaseHTTPRequestHandler):
            def do_GET(self) -> None:
                self.send_response(200)
                self.send_header("Content-Type", "video/mp2t")
                self.end_headers()
                try:
                    server._send(self.wfile)
                except (BrokenPipeError, ConnectionResetError):
                    pass  # the reader hung up (e.g. it was stopped)
                finally:
                    server.done.set()

            def log_message(self, *args: object) -> None:
                pass

        self.httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.url = f"http://127.0.0.1:{self.httpd.server_address[1]}/live.ts"

    def _send(self, wfile: object) -> None:
        h, w = self.frames[0].shape[:2]
        out = av.open(wfile, "w", format="mpegts")
        stream = out.add_stream("mpeg1video", rate=Fraction(25))
        stream.width, stream.height, stream.pix_fmt = w, h, "yuv420p"
        stream.bit_rate = 8_000_000
        try:
            for frame in self.frames:
                for packet in stream.encode(av.VideoFrame.from_ndarray(frame, format="bgr24")):
                    out.mux(packet)
                wfile.flush()  # type: ignore[attr-defined]
                self.sent += 1
                time.sleep(self.pace)
            for packet in stream.encode(None):
                out.mux(packet)
        finally:
            with contextlib.suppress(Exception):
                out.close()


@contextlib.contextmanager
def serve_stream(frames: Sequence[NDArray[np.uint8]], pace: float = 0.0) -> Iterator[StreamServer]:
    """Serve `frames` over HTTP, one every `pace` seconds, for the duration of the block."""
    server = StreamServer(frames, pace)
    thread = threading.Thread(target=server.httpd.serve_forever, daemon=True)
    thread.start()
    try:
        yield server
    finally:
        server.httpd.shutdown()
        server.httpd.server_close()
