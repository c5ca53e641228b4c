// The still camera's measurement (python/pftrack/tracking/camera.py): Lucas-Kanade flow of a few
// corners at one level, and the closed-form similarity fit of matched points.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pftrack/check.hpp"

namespace pftrack {

/// A grey uint8 image: `rows` x `cols` pixels, row `r` at `data + r * stride`.
struct GreyImage {
    const std::uint8_t* data;
    int rows;
    int cols;
    std::ptrdiff_t stride;
    const std::uint8_t* row(int r) const { return data + static_cast<std::ptrdiff_t>(r) * stride; }
};

namespace flow_detail {

/// Index `p` of a row or column of `len` mapped into [0, len) by reflection about the edge
/// pixels (OpenCV's BORDER_REFLECT_101: -1 -> 1, len -> len - 2), repeated for short sides.
inline int reflect_101(int p, int len) {
    if (len == 1) return 0;
    while (p < 0 || p >= len) p = p < 0 ? -p : 2 * len - 2 - p;
    return p;
}

/// OpenCV's cvFloor and cvRound of a float (round half to even, as cvtss2si).
inline int floor_f(float v) {
    const int i = static_cast<int>(v);
    return i - (static_cast<float>(i) > v ? 1 : 0);
}
inline int round_f(float v) { return static_cast<int>(std::lrint(v)); }

constexpr int kWBits = 14;                            // bilinear weights in 1/2^14
constexpr float kFltScale = 1.f / (1 << 20);          // the sums' scale (OpenCV's FLT_SCALE)
inline int descale(int x, int n) { return (x + (1 << (n - 1))) >> n; }

/// The four bilinear weights of fractional offsets (a, b), in 1/2^14, summing to 2^14.
struct Weights {
    int w00, w01, w10, w11;
    Weights(float a, float b) {
        w00 = round_f((1.f - a) * (1.f - b) * static_cast<float>(1 << kWBits));
        w01 = round_f(a * (1.f - b) * static_cast<float>(1 << kWBits));
        w10 = round_f((1.f - a) * b * static_cast<float>(1 << kWBits));
        w11 = (1 << kWBits) - w00 - w01 - w10;
    }
};

/// Scharr derivatives (d/dx, d/dy, both 32 times the gradient) of pixel (r, c) of `img`, rows
/// and columns beyond the edges reflected (-1 -> 1) as OpenCV's calcScharrDeriv does; 0 outside
/// the image (its derivative border is constant 0).
inline void scharr_at(const GreyImage& img, int r, int c, int& dx, int& dy) {
    if (r < 0 || r >= img.rows || c < 0 || c >= img.cols) {
        dx = dy = 0;
        return;
    }
    const int n = img.rows, m = img.cols;
    const int ru = r > 0 ? r - 1 : (n > 1 ? 1 : 0), rd = r < n - 1 ? r + 1 : (n > 1 ? n - 2 : 0);
    const int cl = c > 0 ? c - 1 : (m > 1 ? 1 : 0), cr = c < m - 1 ? c + 1 : (m > 1 ? m - 2 : 0);
    const std::uint8_t *u = img.row(ru), *o = img.row(r), *d = img.row(rd);
    // smoothed across rows (3, 10, 3), then differenced across columns, and the other way round
    const int sl = 3 * (u[cl] + d[cl]) + 10 * o[cl], sr = 3 * (u[cr] + d[cr]) + 10 * o[cr];
    const int tl = d[cl] - u[cl], tc = d[c] - u[c], tr = d[cr] - u[cr];
    dx = sr - sl;
    dy = 3 * (tl + tr) + 10 * tc;
}

}  // namespace flow_detail

/// Lucas-Kanade optical flow of `n` points `pts` (x, y pairs) of `prev` into `next` (same size)
/// on the images alone (no pyramid), as OpenCV's ``calcOpticalFlowPyrLK(prev, next, pts, None,
/// winSize=(win_w, win_h), maxLevel=0, criteria=(COUNT | EPS, max_count, epsilon), flags=0,
/// minEigThreshold=min_eig)`` computes it on x86-64 (its SSE path), to the bit: the same integer
/// bilinear weights and descaled window values, the float sums of the same integer products in
/// the same order (four lanes over the first multiple of 8 columns of a row, then the rest one
/// by one), the same steps and stops, the point refused when its window or its place leaves
/// the image by more than a window. Pixels beyond the edges are reflected (BORDER_REFLECT_101,
/// the pyramid's border); derivatives are 0 there. Only the derivatives inside each point's
/// window are computed, where OpenCV makes them for the whole image: that is the saving.
/// Writes the points' places to `out` (2n floats) and 1/0 (followed or not) to `status`.
inline void still_flow(const GreyImage& prev, const GreyImage& next, const float* pts, int n,
                       float* out, std::uint8_t* status, int win_w, int win_h, int max_count,
                       double epsilon, float min_eig) {
    using namespace flow_detail;
    const float half_w = static_cast<float>(win_w - 1) * 0.5f;
    const float half_h = static_cast<float>(win_h - 1) * 0.5f;
    const double eps2 = epsilon * epsilon;
    const int area = win_w * win_h;
    const int simd_w = (win_w / 8) * 8;  // columns summed in four lanes
    std::vector<int> ival(static_cast<std::size_t>(area)), ix(ival.size()), iy(ival.size());
    std::vector<int> dxs(static_cast<std::size_t>((win_w + 1) * (win_h + 1))), dys(dxs.size());
    std::vector<const std::uint8_t*> rowp(static_cast<std::size_t>(win_h + 1));
    std::vector<int> colx(static_cast<std::size_t>(win_w + 1));
    const auto window = [&](const GreyImage& img, int x0, int y0) {
        for (int y = 0; y <= win_h; ++y) rowp[y] = img.row(reflect_101(y0 + y, img.rows));
        for (int x = 0; x <= win_w; ++x) colx[x] = reflect_101(x0 + x, img.cols);
    };
    for (int p = 0; p < n; ++p) {
        status[p] = 1;
        float px = pts[2 * p], py = pts[2 * p + 1];
        float nx = px, ny = py;  // no initial guess: the flow starts at the point itself
        out[2 * p] = nx;
        out[2 * p + 1] = ny;
        px -= half_w;
        py -= half_h;
        const int ipx = floor_f(px), ipy = floor_f(py);
        if (ipx < -win_w || ipx >= prev.cols || ipy < -win_h || ipy >= prev.rows) {
            status[p] = 0;
            continue;
        }
        const Weights w(px - static_cast<float>(ipx), py - static_cast<float>(ipy));
        window(prev, ipx, ipy);
        for (int y = 0; y <= win_h; ++y)
            for (int x = 0; x <= win_w; ++x)
                scharr_at(prev, ipy + y, ipx + x, dxs[y * (win_w + 1) + x], dys[y * (win_w + 1) + x]);
        float a11 = 0, a12 = 0, a22 = 0;   // the tail columns, one by one
        float l11[4] = {0, 0, 0, 0}, l12[4] = {0, 0, 0, 0}, l22[4] = {0, 0, 0, 0};  // the lanes
        for (int y = 0; y < win_h; ++y) {
            const std::uint8_t *s0 = rowp[y], *s1 = rowp[y + 1];
            const int* dx0 = &dxs[y * (win_w + 1)];
            const int* dy0 = &dys[y * (win_w + 1)];
            const int* dx1 = dx0 + (win_w + 1);
            const int* dy1 = dy0 + (win_w + 1);
            for (int x = 0; x < win_w; ++x) {
                const int k = y * win_w + x;
                ival[k] = descale(s0[colx[x]] * w.w00 + s0[colx[x + 1]] * w.w01 +
                                      s1[colx[x]] * w.w10 + s1[colx[x + 1]] * w.w11,
                                  kWBits - 5);
                const int gx = descale(dx0[x] * w.w00 + dx0[x + 1] * w.w01 + dx1[x] * w.w10 +
                                           dx1[x + 1] * w.w11, kWBits);
                const int gy = descale(dy0[x] * w.w00 + dy0[x + 1] * w.w01 + dy1[x] * w.w10 +
                                           dy1[x + 1] * w.w11, kWBits);
                ix[k] = gx;
                iy[k] = gy;
                // products below 2^24: exact in float; only the sums' order rounds
                const float fx = static_cast<float>(gx), fy = static_cast<float>(gy);
                if (x < simd_w) {
                    const int l = x & 3;
                    l11[l] += fx * fx;
                    l12[l] += fx * fy;
                    l22[l] += fy * fy;
                } else {
                    a11 += static_cast<float>(gx * gx);
                    a12 += static_cast<float>(gx * gy);
                    a22 += static_cast<float>(gy * gy);
                }
            }
        }
        // the lanes summed as OpenCV's v_reduce_sum on SSE does: (l0 + l2) + (l1 + l3)
        a11 += (l11[0] + l11[2]) + (l11[1] + l11[3]);
        a12 += (l12[0] + l12[2]) + (l12[1] + l12[3]);
        a22 += (l22[0] + l22[2]) + (l22[1] + l22[3]);
        const float A11 = a11 * kFltScale, A12 = a12 * kFltScale, A22 = a22 * kFltScale;
        float det = A11 * A22 - A12 * A12;
        const float eig = (A22 + A11 - std::sqrt((A11 - A22) * (A11 - A22) + 4.f * A12 * A12)) /
                          static_cast<float>(2 * area);
        if (eig < min_eig || det < 1.1920929e-07f) {  // FLT_EPSILON
            status[p] = 0;
            continue;
        }
        det = 1.f / det;
        nx -= half_w;
        ny -= half_h;
        float prev_dx = 0, prev_dy = 0;
        for (int j = 0; j < max_count; ++j) {
            const int inx = floor_f(nx), iny = floor_f(ny);
            if (inx < -win_w || inx >= next.cols || iny < -win_h || iny >= next.rows) {
                status[p] = 0;
                break;
            }
            const Weights v(nx - static_cast<float>(inx), ny - static_cast<float>(iny));
            window(next, inx, iny);
            float b1 = 0, b2 = 0;
            float q0[4] = {0, 0, 0, 0}, q1[4] = {0, 0, 0, 0};  // OpenCV's qb0, qb1
            for (int y = 0; y < win_h; ++y) {
                const std::uint8_t *j0 = rowp[y], *j1 = rowp[y + 1];
                const int* iv = &ival[y * win_w];
                const int* gx = &ix[y * win_w];
                const int* gy = &iy[y * win_w];
                int diff[8];
                for (int x0 = 0; x0 < simd_w; x0 += 8) {
                    for (int t = 0; t < 8; ++t) {
                        const int x = x0 + t;
                        diff[t] = descale(j0[colx[x]] * v.w00 + j0[colx[x + 1]] * v.w01 +
                                              j1[colx[x]] * v.w10 + j1[colx[x + 1]] * v.w11,
                                          kWBits - 5) - iv[x];
                    }
                    // pairs (t, t + 4) summed as int32 (exact), then to float, in lanes
                    // [x of t, y of t, x of t+1, y of t+1] for t = 0 (q0) and t = 2 (q1)
                    for (int h = 0; h < 2; ++h) {
                        float* q = h == 0 ? q0 : q1;
                        for (int u = 0; u < 2; ++u) {
                            const int t = 2 * h + u, x = x0 + t;
                            q[2 * u] += static_cast<float>(diff[t] * gx[x] + diff[t + 4] * gx[x + 4]);
                            q[2 * u + 1] +=
                                static_cast<float>(diff[t] * gy[x] + diff[t + 4] * gy[x + 4]);
                        }
                    }
                }
                for (int x = simd_w; x < win_w; ++x) {
                    const int d = descale(j0[colx[x]] * v.w00 + j0[colx[x + 1]] * v.w01 +
                                              j1[colx[x]] * v.w10 + j1[colx[x + 1]] * v.w11,
                                          kWBits - 5) - iv[x];
                    b1 += static_cast<float>(d * gx[x]);
                    b2 += static_cast<float>(d * gy[x]);
                }
            }
            // OpenCV: s = qb0 + qb1; b1 += s0 + s2, b2 += s1 + s3
            const float s0 = q0[0] + q1[0], s1 = q0[1] + q1[1], s2 = q0[2] + q1[2],
                        s3 = q0[3] + q1[3];
            b1 += s0 + s2;
            b2 += s1 + s3;
            b1 *= kFltScale;
            b2 *= kFltScale;
            const float ddx = (A12 * b2 - A22 * b1) * det;
            const float ddy = (A12 * b1 - A11 * b2) * det;
            nx += ddx;
            ny += ddy;
            out[2 * p] = nx + half_w;
            out[2 * p + 1] = ny + half_h;
            if (static_cast<double>(ddx) * ddx + static_cast<double>(ddy) * ddy <= eps2) break;
            if (j > 0 && std::abs(ddx + prev_dx) < 0.01 && std::abs(ddy + prev_dy) < 0.01) {
                out[2 * p] -= ddx * 0.5f;
                out[2 * p + 1] -= ddy * 0.5f;
                break;
            }
            prev_dx = ddx;
            prev_dy = ddy;
        }
        if (status[p]) {  // OpenCV's error pass refuses a place whose window left the image
            const int ex = floor_f(out[2 * p] - half_w), ey = floor_f(out[2 * p + 1] - half_h);
            if (ex < -win_w || ex >= next.cols || ey < -win_h || ey >= next.rows) status[p] = 0;
        }
    }
}

/// The similarity ``[[a, -b, tx], [b, a, ty]]`` minimising the squared distances from it applied
/// to `src` (n points, x y pairs) to `dst`, in closed form: the residuals are linear in
/// (a, b, tx, ty), so this is the minimum that OpenCV's Levenberg-Marquardt refinement in
/// ``estimateAffinePartial2D`` iterates towards (its result differs in the last bits). Centred on
/// the means, a = sum(x X + y Y) / sum(x^2 + y^2), b = sum(x Y - y X) / sum(x^2 + y^2). Writes the
/// six values row by row to `out`; returns false (nothing written) when the points of `src` all
/// coincide (n < 2, or no spread).
inline bool similarity_fit(const float* src, const float* dst, int n, double* out) {
    if (n < 2) return false;
    double mx = 0, my = 0, mX = 0, mY = 0;
    for (int i = 0; i < n; ++i) {
        mx += src[2 * i];
        my += src[2 * i + 1];
        mX += dst[2 * i];
        mY += dst[2 * i + 1];
    }
    mx /= n;
    my /= n;
    mX /= n;
    mY /= n;
    double ss = 0, sa = 0, sb = 0;
    for (int i = 0; i < n; ++i) {
        const double x = src[2 * i] - mx, y = src[2 * i + 1] - my;
        const double X = dst[2 * i] - mX, Y = dst[2 * i + 1] - mY;
        ss += x * x + y * y;
        sa += x * X + y * Y;
        sb += x * Y - y * X;
    }
    if (!(ss > 0)) return false;
    const double a = sa / ss, b = sb / ss;
    out[0] = a;
    out[1] = -b;
    out[2] = mX - (a * mx - b * my);
    out[3] = b;
    out[4] = a;
    out[5] = mY - (b * mx + a * my);
    return true;
}

}  // namespace pftrack
