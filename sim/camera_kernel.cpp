// Compiled stages of the camera renderer (sim/camera.py, loaded by sim/camera_kernel.py), each
// giving exactly what the numpy code it replaces gives:
// - fr_camera_hits: every column ray against every wall and cylinder band, the hit's depth and
//   shade. The same IEEE operations in the same order as the numpy expressions (+ - * / and
//   sqrt are exact; no contraction into fused multiply-adds: -ffp-contract=off).
// - fr_camera_layers: a level camera's depth layers and runs of rows per column, as
//   CameraRenderer._runs computes them with ties in depth taken in surface order (its numpy
//   sort is stable too); rows by the pinhole formula with the same operations.
// - fr_camera_paint: every column's runs of rows painted straight into the RGB888 image with
//   the sensor noise added in the same pass. Integer work only, the same as the numpy path
//   (run ids by cumulative sum, palette lookup, RGBA to RGB, table lookup, saturating add).
#include <cmath>
#include <cstdint>
#include <algorithm>
#include <cstring>
#include <vector>

#define FR_EXPORT extern "C" __attribute__((visibility("default")))

FR_EXPORT int fr_camera_kernel_version() { return 3; }

static inline double positive_part(double x) { return x > 0.0 ? x : 0.0; }  // np.maximum(0, x)

// Column c's ray has direction (dx[c], dy[c]) with a forward component of 1, so the ray
// parameter is the depth. Walls: start (wx0, wy0), vector (wex, wey), shade per wall (wshade).
// Cylinders: centre (cx_, cy_), radius; bands: owner cylinder. Output (width, walls + bands)
// row-major: depth (inf for no hit) and shade.
FR_EXPORT void fr_camera_hits(int64_t width, const double *dx, const double *dy,
                              const double *slope_sq1, double px, double py, int64_t n_walls,
                              const double *wx0, const double *wy0, const double *wex,
                              const double *wey, const double *wshade, int64_t n_cyls,
                              const double *cx_, const double *cy_, const double *radius,
                              int64_t n_bands, const int64_t *owner, double near,
                              double ambient, double intensity, double lx, double ly,
                              double *cyl_t, double *cyl_shade, double *depth, double *shade) {
    const double inf = INFINITY;
    const int64_t n = n_walls + n_bands;
    for (int64_t c = 0; c < width; ++c) {
        const double ddx = dx[c], ddy = dy[c], a = slope_sq1[c];
        double *d = depth + c * n, *s = shade + c * n;
        for (int64_t i = 0; i < n_walls; ++i) {
            const double qx = wx0[i] - px, qy = wy0[i] - py;
            const double denom = ddx * wey[i] - ddy * wex[i];
            const double t = (qx * wey[i] - qy * wex[i]) / denom;
            const double u = (qx * ddy - qy * ddx) / denom;
            d[i] = (u >= 0.0 && u <= 1.0 && t > near) ? t : inf;
            s[i] = wshade[i];
        }
        for (int64_t j = 0; j < n_cyls; ++j) {
            const double qx = px - cx_[j], qy = py - cy_[j], r = radius[j];
            const double b = ddx * qx + ddy * qy;
            const double cc = qx * qx + qy * qy - r * r;
            const double disc = b * b - a * cc;
            double t = (-b - std::sqrt(disc)) / a;
            t = (disc >= 0.0 && t > near && cc > 0.0) ? t : inf;
            const double th = t < inf ? t : 0.0;
            const double ndotl = ((qx + th * ddx) * lx + (qy + th * ddy) * ly) / r;
            cyl_t[j] = t;
            cyl_shade[j] = ambient + intensity * positive_part(-ndotl);
        }
        for (int64_t k = 0; k < n_bands; ++k) {
            d[n_walls + k] = cyl_t[owner[k]];
            s[n_walls + k] = cyl_shade[owner[k]];
        }
    }
}

// starts: (width, runs) int32, each column's run start rows ascending, the first 0 (a start
// equal to height begins no run). palette: (width * runs) packed RGBA, bytes r, g, b, a.
// noise: nullptr, or (height * width * 3) uint16 indices into the int8 table, one per byte
// of the image in row-major order.
FR_EXPORT void fr_camera_paint(const int32_t *starts, int64_t runs, const uint32_t *palette,
                               int64_t width, int64_t height, uint8_t *rgb,
                               const uint16_t *noise, const int8_t *table) {
    std::vector<int64_t> run(width, 0);  // each column's current run
    for (int64_t y = 0; y < height; ++y) {
        uint8_t *out = rgb + 3 * y * width;
        const uint16_t *idx = noise ? noise + 3 * y * width : nullptr;
        for (int64_t c = 0; c < width; ++c) {
            const int32_t *s = starts + c * runs;
            int64_t j = run[c];
            while (j + 1 < runs && s[j + 1] <= y)
                ++j;
            run[c] = j;
            uint8_t px[4];
            std::memcpy(px, palette + c * runs + j, 4);
            if (idx) {
                for (int k = 0; k < 3; ++k) {
                    int v = px[k] + table[idx[3 * c + k]];
                    out[3 * c + k] = static_cast<uint8_t>(v < 0 ? 0 : (v > 255 ? 255 : v));
                }
            } else {
                out[3 * c] = px[0];
                out[3 * c + 1] = px[1];
                out[3 * c + 2] = px[2];
            }
        }
    }
}

static inline uint32_t packed(double r, double g, double b) {  // sim/camera.py _packed_colors
    auto byte = [](double v) {
        v = v * 255.0 + 0.5;
        v = v < 0.0 ? 0.0 : (v > 255.0 ? 255.0 : v);
        return static_cast<uint32_t>(static_cast<uint8_t>(v));
    };
    return byte(r) | (byte(g) << 8) | (byte(b) << 16);
}

// depth, shade: (width, n) from fr_camera_hits; z0, z1: (n) clipped heights; albedo (n, 3).
// Writes starts (width, 2k + 2) and palette (width * (2k + 2)) compactly and returns k, the
// layers drawn (0: no column sees any surface; nothing written).
FR_EXPORT int64_t fr_camera_layers(int64_t width, int64_t height, int64_t n,
                                   const double *depth, const double *shade, const double *z0,
                                   const double *z1, const double *albedo, double cam_h,
                                   double row_axis, double focal, int64_t max_layers,
                                   int64_t horizon, uint32_t ceil_rgba, uint32_t floor_rgba,
                                   int32_t *starts, uint32_t *palette) {
    int64_t most = 0;
    for (int64_t c = 0; c < width; ++c) {
        int64_t hits = 0;
        for (int64_t i = 0; i < n; ++i)
            hits += depth[c * n + i] < INFINITY;
        most = std::max(most, hits);
    }
    if (most == 0)
        return 0;
    const int64_t k = std::min(max_layers, most), m = std::min(2 * k, most), runs = 2 * k + 2;
    const int64_t H = height;
    std::vector<int64_t> cand(n), sel(k + 1);
    std::vector<int64_t> rs(m), re(m), lrs(k + 1), lre(k + 1);
    std::vector<char> hidden(m);
    std::vector<uint32_t> colors(k + 2);
    std::vector<int32_t> st(runs);
    for (int64_t c = 0; c < width; ++c) {
        const double *d = depth + c * n, *sh = shade + c * n;
        for (int64_t i = 0; i < n; ++i)
            cand[i] = i;
        std::partial_sort(cand.begin(), cand.begin() + m, cand.end(), [d](int64_t a, int64_t b) {
            return d[a] < d[b] || (d[a] == d[b] && a < b);
        });
        for (int64_t j = 0; j < m; ++j) {
            const int64_t i = cand[j];
            const bool hit = std::isfinite(d[i]);
            const double p = hit ? d[i] : 1.0;
            double a = std::ceil(row_axis - focal * ((z1[i] - cam_h) / p));
            double b = std::floor(row_axis - focal * ((z0[i] - cam_h) / p)) + 1.0;
            a = a < 0.0 ? 0.0 : (a > H ? static_cast<double>(H) : a);
            b = b < 0.0 ? 0.0 : (b > H ? static_cast<double>(H) : b);
            rs[j] = hit ? static_cast<int64_t>(a) : H;
            re[j] = hit ? static_cast<int64_t>(b) : H;
        }
        if (m == k) {
            for (int64_t j = 0; j < k; ++j) {
                sel[j] = cand[j];
                lrs[j] = rs[j];
                lre[j] = re[j];
            }
        } else {
            // Hidden: the rows lie within a nearer candidate's, or there are none.
            for (int64_t j = 0; j < m; ++j) {
                bool h = rs[j] >= re[j];
                for (int64_t i = 0; i < j && !h; ++i)
                    h = rs[i] <= rs[j] && re[i] >= re[j];
                hidden[j] = h;
            }
            // The first k visible candidates by depth, then hidden ones (drawn as nothing).
            int64_t out = 0;
            for (int pass = 0; pass < 2 && out < k; ++pass)
                for (int64_t j = 0; j < m && out < k; ++j)
                    if (hidden[j] == pass) {
                        sel[out] = cand[j];
                        lrs[out] = pass ? H : rs[j];
                        lre[out] = pass ? H : re[j];
                        ++out;
                    }
        }
        lrs[k] = 0;  // the sentinel layer covers every row: "no surface here"
        lre[k] = H + 1;
        for (int64_t l = 0; l < k; ++l) {
            const int64_t i = sel[l];
            const double *al = albedo + 3 * i;
            colors[l] = packed(al[0] * sh[i], al[1] * sh[i], al[2] * sh[i]);
        }
        colors[k] = ceil_rgba;
        colors[k + 1] = floor_rgba;
        st[0] = 0;
        st[1] = static_cast<int32_t>(horizon);
        for (int64_t l = 0; l < k; ++l) {
            st[2 + l] = static_cast<int32_t>(lrs[l]);
            st[k + 2 + l] = static_cast<int32_t>(lre[l]);
        }
        std::sort(st.begin(), st.end());
        for (int64_t r = 0; r < runs; ++r) {
            const int64_t s = st[r];
            int64_t layer = 0;
            while (!(lrs[layer] <= s && s < lre[layer]))
                ++layer;
            if (layer == k && s >= horizon)
                layer = k + 1;
            starts[c * runs + r] = st[r];
            palette[c * runs + r] = colors[layer];
        }
    }
    return k;
}
