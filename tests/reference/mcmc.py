"""NumPy references for the MCMC samplers: each follows the documented semantics
(docs/samplers.md, the comments of mh.hpp and rjmcmc.hpp), not the C++ code."""

from __future__ import annotations

import math

import numpy as np

from tests.reference import kernels

MASK64 = (1 << 64) - 1


# ---- counter-based random numbers (rng.hpp's documented SplitMix64 + Box-Muller) ----
def mix64(z: int) -> int:
    z = (z + 0x9E3779B97F4A7C15) & MASK64
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK64
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK64
    return z ^ (z >> 31)


class CounterRng:
    def __init__(self, seed: int, stream: int) -> None:
        self.key = mix64(seed ^ mix64((stream + 0x5851F42D4C957F2D) & MASK64))

    def uniform(self, k: int) -> float:
        return (mix64(self.key ^ mix64(k & MASK64)) >> 11) * 2.0**-53

    def normal(self, k: int) -> float:
        u1 = 1.0 - self.uniform(2 * k)
        u2 = self.uniform(2 * k + 1)
        return math.sqrt(-2.0 * math.log(u1)) * math.cos(6.283185307179586 * u2)


# ---- boxes, histograms, likelihood ----
def box_pixels(cx, cy, w, h, rows, cols):
    x0 = max(0, math.floor(cx - 0.5 * w + 0.5))
    x1 = min(cols, math.floor(cx + 0.5 * w + 0.5))
    y0 = max(0, math.floor(cy - 0.5 * h + 0.5))
    y1 = min(rows, math.floor(cy + 0.5 * h + 0.5))
    return x0, x1, y0, y1


def box_mask(rng_box, shape):
    x0, x1, y0, y1 = rng_box
    m = np.zeros(shape, bool)
    if x0 < x1 and y0 < y1:
        m[y0:y1, x0:x1] = True
    return m


def iou_cxcywh(a, b):
    """IoU of two (cx, cy, w, h) boxes, continuous coordinates."""
    iw = min(a[0] + a[2] / 2, b[0] + b[2] / 2) - max(a[0] - a[2] / 2, b[0] - b[2] / 2)
    ih = min(a[1] + a[3] / 2, b[1] + b[3] / 2) - max(a[1] - a[3] / 2, b[1] - b[3] / 2)
    if iw <= 0 or ih <= 0:
        return 0.0
    return iw * ih / (a[2] * a[3] + b[2] * b[3] - iw * ih)


def histogram(bins, n_bins, box, step=1):
    """Normalised histogram and counted pixels of a box; with `step` > 1 of its pixels whose
    column and row are multiples of `step` only (counted: those points)."""
    x0, x1, y0, y1 = box_pixels(*box, *bins.shape)
    x0, y0 = -(-x0 // step) * step, -(-y0 // step) * step  # the first multiples of step
    if x0 >= x1 or y0 >= y1:
        return np.zeros(n_bins), 0.0
    b = bins[y0:y1:step, x0:x1:step].ravel()
    b = b[b >= 0]
    h = np.bincount(b, minlength=n_bins).astype(float)
    total = h.sum()
    return (h / total if total > 0 else h), float(total)


def colour_loglik(bins, n_bins, box, ref, lam, step=1):
    h, _ = histogram(bins, n_bins, box, step)
    rho = np.sum(np.sqrt(h * ref / ref.sum()))
    return -lam * max(0.0, 1.0 - min(rho, 1.0))


# ---- Metropolis-Hastings step (mh.hpp's documented draw layout), equal-weight input ----
def mh_step(
    particles,
    bins,
    n_bins,
    ref,
    w0,
    h0,
    a,
    b,
    sigma,
    s_min,
    s_max,
    lam,
    seed,
    step,
    n_iter,
    burn_in,
    proposal,
    rw_sigma,
    lattice=1,
    details=None,
):
    """Returns (new particles, mean estimate, acceptance). Input weights must be equal
    (systematic resampling then keeps every particle in order). `lattice` > 1 counts each box
    on the lattice of that step (kernels.box_histograms(..., step), as the SIS reference does);
    `details`, a dict, gets each final particle's "rho" and "counted" (pixels, or lattice
    points times step^2)."""
    rng = CounterRng(seed, step)
    out = particles.copy()
    a, b, sigma, rw_sigma = (np.asarray(v, float) for v in (a, b, sigma, rw_sigma))

    def log_dyn(x, mu):
        if not s_min <= x[2] <= s_max:
            return -np.inf
        fixed = sigma == 0  # a deterministic component: no mass off its prediction
        if np.any((x != mu) & fixed):
            return -np.inf
        return -0.5 * np.sum(((x - mu)[~fixed] / sigma[~fixed]) ** 2)

    def box_of(x):
        return (x[0], x[1], x[2] * w0, x[2] * h0)

    def rho_counted(x):
        if lattice == 1:
            h, counted = histogram(bins, n_bins, box_of(x))
        else:
            h = kernels.box_histograms(bins, n_bins, [box_of(x)], "uniform", lattice)[0]
            x0, x1, y0, y1 = box_pixels(*box_of(x), *bins.shape)
            x0, y0 = -(-x0 // lattice) * lattice, -(-y0 // lattice) * lattice
            patch = bins[y0:y1:lattice, x0:x1:lattice]
            counted = float(np.count_nonzero(patch >= 0)) * lattice**2
        return float(np.sum(np.sqrt(h * ref / ref.sum()))), counted

    def loglik(x):
        if lattice == 1:
            return colour_loglik(bins, n_bins, box_of(x), ref, lam)
        rho, _ = rho_counted(x)
        return -lam * max(0.0, 1.0 - min(rho, 1.0))

    acc = prop = 0
    total = np.zeros(3)
    n = len(particles)
    mus = a * particles[:, :3] + b * particles[:, 3:]
    for i in range(n):
        par = i
        base = lambda j, i=i: 4 * (i * (n_iter + 1) + j)  # noqa: E731
        x = mus[par] + sigma * np.array([rng.normal(base(0) + d) for d in range(3)])
        x[2] = min(max(x[2], s_min), s_max)
        cur = loglik(x) + log_dyn(x, mus[par])
        for it in range(1, n_iter + 1):
            k = base(it)
            w = np.array([rng.normal(k + d) for d in range(3)])
            if proposal == "dynamics":  # a parent j* of the whole set, then its dynamics
                par_s = min(n - 1, int(rng.uniform(2 * (k + 3) + 1) * n))
                xs = mus[par_s] + sigma * w
            else:
                par_s = par
                xs = x + rw_sigma * w
            ld = log_dyn(xs, mus[par_s])
            ok = False
            if np.isfinite(ld):
                new = loglik(xs) + ld
                # eq. 5 with q = dynamics mixture (q ratio = prior ratio) or a symmetric walk;
                # a current state of target 0 is left by any proposal of positive target
                log_a = new - cur if np.isfinite(cur) else np.inf
                if proposal == "dynamics" and np.isfinite(cur):
                    log_a += log_dyn(x, mus[par]) - ld
                ok = log_a >= 0 or rng.uniform(2 * (k + 3)) < math.exp(log_a)
            if ok:
                x, cur, par = xs, new, par_s
            if it > burn_in:
                prop += 1
                acc += ok
                total += x
        out[i, 3:] = particles[par, :3]
        out[i, :3] = x
        if details is not None:
            rho, counted = rho_counted(x)
            details.setdefault("rho", []).append(rho)
            details.setdefault("counted", []).append(counted)
    return out, total / prop, acc / prop


# ---- RJ-MCMC target and proposals (rjmcmc.hpp header comment) ----
class RjReference:
    """The RJ-MCMC model of one frame, from its documented definition."""

    def __init__(self, bins, n_bins, mask, slots, tracks, params, detections=()):
        self.dets = np.asarray(detections, float).reshape(-1, 4)  # all candidates, cx, cy, w, h
        self.bins, self.n_bins = bins, n_bins
        self.fg = np.asarray(mask) != 0
        self.slots, self.p = slots, params
        self.tracks = {t["id"]: t for t in tracks}
        self.a, self.b = np.asarray(params["a"], float), np.asarray(params["b"], float)
        self.sigma = np.asarray(params["sigma"], float)

    def box(self, slot, x):
        s = self.slots[slot]
        return (x[0], x[1], x[2] * s["w0"], x[2] * s["h0"])

    def lattice(self, slot):
        """The step every box of `slot` is counted on this frame: lattice_step of its anchor
        box (the mean prediction's, a newborn's candidate's) and params' min_samples."""
        a = self.slots[slot]["anchor"]
        return kernels.lattice_step(a[2], a[3], self.p.get("min_samples", 0))

    def rng_box(self, slot, x):
        return box_pixels(*self.box(slot, x), *self.bins.shape)

    def mu(self, slot):
        par = self.tracks[self.slots[slot]["id"]]["parents"]
        return self.a * par[:, :3] + self.b * par[:, 3:]

    def log_prior_pos(self, slot, x):
        p = self.p
        if not p["s_min"] <= x[2] <= p["s_max"]:
            return -np.inf
        s = self.slots[slot]
        if s["candidate"] >= 0:
            c = np.array([s["anchor"][0], s["anchor"][1], 1.0])
            sd = np.array([p["birth_sigma_xy"], p["birth_sigma_xy"], p["birth_sigma_s"]])
            return float(np.sum(-0.5 * ((x - c) / sd) ** 2 - np.log(sd) - 0.5 * np.log(2 * np.pi)))
        mu = self.mu(slot)
        comp = np.sum(-0.5 * ((x - mu) / self.sigma) ** 2 - np.log(self.sigma), axis=1)
        comp -= 1.5 * np.log(2 * np.pi)
        m = comp.max()
        return float(m + np.log(np.mean(np.exp(comp - m))))

    def log_omega(self, slot):
        s = self.slots[slot]
        if s["candidate"] >= 0:
            return math.log(self.p["birth_prior"])
        e = min(max(self.p["survival"] * self.tracks[s["id"]]["existence"], 1e-3), 1 - 1e-3)
        return math.log(e / (1 - e))

    def log_target(self, config):
        p, t = self.p, 0.0
        union = np.zeros(self.fg.shape, bool)
        masks = []
        for slot, x in config:
            lp = self.log_prior_pos(slot, x)
            if not np.isfinite(lp):
                return -np.inf
            ref = self.slots[slot]["ref"]
            t += colour_loglik(
                self.bins, self.n_bins, self.box(slot, x), ref, p["lam"], self.lattice(slot)
            )
            t += lp + self.log_omega(slot)
            if len(self.dets):  # detection support delta max_k IoU(b, d_k)
                b = self.box(slot, x)
                t += self.p["detection"] * max(iou_cxcywh(b, d) for d in self.dets)
            m = box_mask(self.rng_box(slot, x), self.fg.shape)
            masks.append(m)
            union |= m
        for i in range(len(masks)):
            for j in range(i + 1, len(masks)):
                inter = np.sum(masks[i] & masks[j])
                if inter:
                    t -= p["interaction"] * inter / np.sum(masks[i] | masks[j])
        c, area = np.sum(union & self.fg), np.sum(union)
        eta = p["background_penalty"]
        return t + p["coverage"] * (c - eta * (area - c)) / max(self.fg.sum(), 1)

    def birth_weight(self, slot, config):
        an = self.slots[slot]["anchor"]
        if self.slots[slot]["candidate"] < 0:  # mean AR2 prediction, scale clamped
            mean = self.mu(slot).mean(axis=0)
            s = min(max(mean[2], self.p["s_min"]), self.p["s_max"])
            an = (mean[0], mean[1], s * self.slots[slot]["w0"], s * self.slots[slot]["h0"])
        am = box_mask(box_pixels(*an, *self.fg.shape), self.fg.shape)
        area = am.sum()
        if area == 0:
            return self.p["birth_eps"]
        share = np.sum(am & self.fg) / area
        for s2, x in config:
            share *= 1 - np.sum(am & box_mask(self.rng_box(s2, x), self.fg.shape)) / area
        return self.p["birth_eps"] + share

    def move_prob(self, m):
        p = self.p
        tot = p["p_birth"] + p["p_death"] + p["p_update"] + p["p_swap"]
        return p["p_" + m] / tot

    def log_q(self, move, config, to, slot):
        """log q(X' | X) of one move."""
        n = len(config)
        if move == "birth":
            present = {s for s, _ in config}
            w = {
                s: self.birth_weight(s, config) for s in range(len(self.slots)) if s not in present
            }
            x = dict(to)[slot]
            return (
                math.log(self.move_prob("birth"))
                + math.log(w[slot] / sum(w.values()))
                + self.log_prior_pos(slot, x)
            )
        if move == "death":
            return math.log(self.move_prob("death") / n)
        if move == "update":
            return math.log(self.move_prob("update") / n) + self.log_prior_pos(slot, dict(to)[slot])
        return math.log(self.move_prob("swap") / (n * (n - 1) / 2))


# ---- RJ-MCMC chain of one frame (rjmcmc.hpp: draw layout, Metropolis-Hastings-Green) ----
MOVES = ("birth", "death", "update", "swap")


def rj_chain(r, tracks, seed, step):
    """One frame of the joint chain on the model `r` (an RjReference whose slots are the
    prepared frame's), from the documented start (every identity of `tracks` with existence
    >= 1/2 at its mean prediction) and draws (iteration k: uniforms 8k move, 8k+1 and 8k+2 the
    proposal's, 8k+3 acceptance of CounterRng(seed, step); normals 4k .. 4k+2 of
    CounterRng(mix64(seed ^ 0xD1B54A32D192ED03), step)). Each move is accepted when
    u < pi(X') q(X|X') / [pi(X) q(X'|X)] with pi and q of the reference: the general ratio of
    Green (1995), not the closed forms of the core.

    Returns (samples, log_targets, accepted, proposed): the kept configurations, each a list
    of (slot, x, prev) sorted by slot, their log pi, and per move the counts over kept
    iterations."""
    p = r.p
    ur = CounterRng(seed, step)
    nr = CounterRng(mix64(seed ^ 0xD1B54A32D192ED03), step)
    cur = []
    for s, t in enumerate(tracks):
        if t["existence"] < 0.5:
            continue
        an = r.slots[s]["anchor"]
        x = np.array([an[0], an[1], min(max(an[2] / t["w0"], p["s_min"]), p["s_max"])])
        cur.append((s, x, t["parents"][:, :3].mean(axis=0)))

    def plain(c):
        return [(s, x) for s, x, _ in c]

    def draw(slot, u, w):
        sl = r.slots[slot]
        if sl["candidate"] >= 0:
            sd = np.array([p["birth_sigma_xy"], p["birth_sigma_xy"], p["birth_sigma_s"]])
            x = np.array([sl["anchor"][0], sl["anchor"][1], 1.0]) + sd * w
            return x, x.copy()  # zero velocity at birth
        mu = r.mu(slot)
        n = min(len(mu) - 1, int(u * len(mu)))
        return mu[n] + r.sigma * w, r.tracks[sl["id"]]["parents"][n, :3].copy()

    probs = np.array([r.move_prob(m) for m in MOVES])
    samples, targets = [], []
    accepted, proposed = dict.fromkeys(MOVES, 0), dict.fromkeys(MOVES, 0)
    for k in range(p["burn_in"] + p["n_samples"]):
        u = ur.uniform(8 * k)
        move = next(
            (m for m, c in zip(MOVES[:3], np.cumsum(probs[:3]), strict=True) if u < c), "swap"
        )
        u1, u2 = ur.uniform(8 * k + 1), ur.uniform(8 * k + 2)
        w = np.array([nr.normal(4 * k + d) for d in range(3)])
        n, new, slot = len(cur), None, -1
        if move == "birth":
            present = {s for s, _, _ in cur}
            absent = [s for s in range(len(r.slots)) if s not in present]
            if absent:
                cum = np.cumsum([r.birth_weight(s, plain(cur)) for s in absent])
                slot = absent[next((j for j in range(len(absent) - 1) if u1 * cum[-1] < cum[j]),
                                   len(absent) - 1)]  # fmt: skip
                new = sorted([*cur, (slot, *draw(slot, u2, w))], key=lambda o: o[0])
        elif move in ("death", "update") and n > 0:
            j = min(n - 1, int(u1 * n))
            slot = cur[j][0]
            new = list(cur)
            if move == "death":
                del new[j]
            else:
                new[j] = (slot, *draw(slot, u2, w))
        elif move == "swap" and n > 1:
            pairs = n * (n - 1) // 2
            q = min(pairs - 1, int(u1 * pairs))
            a = 0
            while q >= n - 1 - a:
                q -= n - 1 - a
                a += 1
            b = a + 1 + q
            new = list(cur)
            new[a] = (cur[a][0], cur[b][1], cur[b][2])
            new[b] = (cur[b][0], cur[a][1], cur[a][2])
        kept = k >= p["burn_in"]
        if new is not None:
            proposed[move] += kept
            reverse = {"birth": "death", "death": "birth"}.get(move, move)
            x, y = plain(cur), plain(new)
            ty = r.log_target(y)
            lr = -np.inf
            if np.isfinite(ty):
                lr = ty + r.log_q(reverse, y, x, slot) - r.log_target(x) - r.log_q(move, x, y, slot)
            if lr >= 0 or ur.uniform(8 * k + 3) < math.exp(lr):
                cur = new
                accepted[move] += kept
        if kept:
            samples.append(cur)
            targets.append(r.log_target(plain(cur)))
    return samples, targets, accepted, proposed


def rj_summary(r, samples, targets):
    """Per slot present in a kept sample: (slot, cx, cy, w, h, existence), the mean state over
    the samples containing it; and the MAP sample's (slot, cx, cy, w, h) rows."""
    rows = []
    for s in range(len(r.slots)):
        xs = [x for c in samples for slot, x, _ in c if slot == s]
        if xs:
            m = np.mean(xs, axis=0)
            w0, h0 = r.slots[s]["w0"], r.slots[s]["h0"]
            rows.append([s, m[0], m[1], m[2] * w0, m[2] * h0, len(xs) / len(samples)])
    best = samples[int(np.argmax(targets))]
    mp = [[s, *r.box(s, x)] for s, x, _ in best]
    return np.array(rows).reshape(-1, 6), np.array(mp).reshape(-1, 5)
