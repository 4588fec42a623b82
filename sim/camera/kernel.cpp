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
#include <immintrin.h>
#include <cstring>
#include <vector>

#define FR_EXPORT extern "C" __attribute__((visibility("default")))

constexpr int64_t MAX_STEPS = 64;  // sim/camera_kernel.py MAX_STEPS

FR_EXPORT int fr_camera_kernel_version() { return 9; }

static inline double positive_part(double x) { return x > 0.0 ? x : 0.0; }  // np.maximum(0, x)

// Column c's ray has direction (ch + slope[c] sh, sh - slope[c] ch) with a forward component
// of 1, so the ray parameter is the depth. walls: (6, n_walls) rows x0, y0, ex, ey, length,
// height; centres: (3, n_cyls) rows x, y, radius; owner: the cylinder of each band. scratch:
// n_walls + 2 n_cyls doubles. Output (width, walls + bands) row-major: depth (inf for no
// hit) and shade.
FR_EXPORT void fr_camera_hits(int64_t width, const double *slope, const double *slope_sq1,
                              double ch, double sh, double px, double py, int64_t n_walls,
                              const double *walls, int64_t n_cyls, const double *centres,
                              int64_t n_bands, const int64_t *owner, double near,
                              double ambient, double intensity, double lx, double ly,
                              double *scratch, double *depth, double *shade) {
    const double inf = INFINITY;
    const int64_t n = n_walls + n_bands;
    const double *wx0 = walls, *wy0 = walls + n_walls, *wex = walls + 2 * n_walls,
                 *wey = walls + 3 * n_walls, *wlen = walls + 4 * n_walls;
    const double *cx_ = centres, *cy_ = centres + n_cyls, *radius = centres + 2 * n_cyls;
    double *wshade = scratch, *cyl_t = scratch + n_walls, *cyl_shade = cyl_t + n_cyls;
    for (int64_t i = 0; i < n_walls; ++i) {
        // Unit normal turned towards the camera (the camera's side of the wall line).
        const double qx = wx0[i] - px, qy = wy0[i] - py;
        const double side = (wey[i] * qx - wex[i] * qy > 0.0 ? -1.0 : 1.0) / wlen[i];
        const double ndotl = side * (wey[i] * lx - wex[i] * ly);
        wshade[i] = ambient + intensity * positive_part(-ndotl);
    }
    for (int64_t c = 0; c < width; ++c) {
        const double ddx = ch + slope[c] * sh, ddy = sh - slope[c] * ch, a = slope_sq1[c];
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

// The noise table is monotone (quantiles of a normal distribution, rounded): table[i] is
// table[0] plus the number of steps at[j] <= i (a step of two levels listed twice). With few
// steps, counting them for 8 or 16 indices at a time (SIMD compares) is faster than looking
// each index up, and gives the same value. out[i] = clean[i] + table[idx[i]], saturated to
// 0..255 (as cv2.add into uint8; packus saturates the same way).
struct Noise {
    const uint16_t *idx;      // one per byte of the image
    const int32_t *block;     // table[i] == sub[block[i >> 8] + (i & 255)]
    const int8_t *sub;
    int64_t steps;            // 0: look every index up
    const uint16_t *at;       // the steps' first indices (>= 1), ascending
    int16_t base;             // table[0]
};

static inline uint8_t saturated(int v) {
    return static_cast<uint8_t>(v < 0 ? 0 : (v > 255 ? 255 : v));
}

// Restrict: the byte stores may otherwise alias every pointer, reloaded after each one.
static void noise_lookup(uint8_t *__restrict out, const uint8_t *__restrict clean,
                         const uint16_t *__restrict idx, int64_t from, int64_t n,
                         const int32_t *__restrict block, const int8_t *__restrict sub) {
    for (int64_t i = from; i < n; ++i)
        out[i] = saturated(clean[i] + sub[block[idx[i] >> 8] + (idx[i] & 255)]);
}

// idx >= at as a signed 16-bit compare: both with the top bit flipped, and at - 1 (at >= 1).
static inline int16_t flipped_step(uint16_t at) {
    return static_cast<int16_t>(static_cast<uint16_t>(at - 1) ^ 0x8000u);
}

// SSE2 (every x86-64): 16 bytes an iteration; returns where the rest starts.
static int64_t noise_count_sse2(uint8_t *out, const uint8_t *clean, const uint16_t *idx,
                                int64_t n, const Noise &z) {
    const __m128i flip = _mm_set1_epi16(static_cast<int16_t>(0x8000)), zero = _mm_setzero_si128();
    const __m128i base = _mm_set1_epi16(z.base);
    __m128i at[MAX_STEPS];
    const int64_t steps = z.steps;
    for (int64_t j = 0; j < steps; ++j)
        at[j] = _mm_set1_epi16(flipped_step(z.at[j]));
    const int64_t whole = n - n % 16;
    for (int64_t i = 0; i < whole; i += 16) {
        const __m128i x0 = _mm_xor_si128(_mm_loadu_si128((const __m128i *)(idx + i)), flip);
        const __m128i x1 = _mm_xor_si128(_mm_loadu_si128((const __m128i *)(idx + i + 8)), flip);
        const __m128i c = _mm_loadu_si128((const __m128i *)(clean + i));
        __m128i v0 = _mm_add_epi16(_mm_unpacklo_epi8(c, zero), base);
        __m128i v1 = _mm_add_epi16(_mm_unpackhi_epi8(c, zero), base);
        for (int64_t j = 0; j < steps; ++j) {  // a true compare is -1: subtract it
            v0 = _mm_sub_epi16(v0, _mm_cmpgt_epi16(x0, at[j]));
            v1 = _mm_sub_epi16(v1, _mm_cmpgt_epi16(x1, at[j]));
        }
        _mm_storeu_si128((__m128i *)(out + i), _mm_packus_epi16(v0, v1));
    }
    return whole;
}

// AVX2 where the CPU has it: 32 bytes an iteration.
__attribute__((target("avx2"))) static int64_t noise_count_avx2(uint8_t *out,
                                                                const uint8_t *clean,
                                                                const uint16_t *idx, int64_t n,
                                                                const Noise &z) {
    const __m256i flip = _mm256_set1_epi16(static_cast<int16_t>(0x8000));
    const __m256i base = _mm256_set1_epi16(z.base);
    __m256i at[MAX_STEPS];
    const int64_t steps = z.steps;
    for (int64_t j = 0; j < steps; ++j)
        at[j] = _mm256_set1_epi16(flipped_step(z.at[j]));
    const int64_t whole = n - n % 32;
    for (int64_t i = 0; i < whole; i += 32) {
        const __m256i x0 = _mm256_xor_si256(_mm256_loadu_si256((const __m256i *)(idx + i)), flip);
        const __m256i x1 =
            _mm256_xor_si256(_mm256_loadu_si256((const __m256i *)(idx + i + 16)), flip);
        __m256i v0 = _mm256_add_epi16(
            _mm256_cvtepu8_epi16(_mm_loadu_si128((const __m128i *)(clean + i))), base);
        __m256i v1 = _mm256_add_epi16(
            _mm256_cvtepu8_epi16(_mm_loadu_si128((const __m128i *)(clean + i + 16))), base);
        for (int64_t j = 0; j < steps; ++j) {
            v0 = _mm256_sub_epi16(v0, _mm256_cmpgt_epi16(x0, at[j]));
            v1 = _mm256_sub_epi16(v1, _mm256_cmpgt_epi16(x1, at[j]));
        }
        // packus works within 128-bit lanes: put the four 8-byte quarters back in order.
        const __m256i packed = _mm256_packus_epi16(v0, v1);
        _mm256_storeu_si256((__m256i *)(out + i), _mm256_permute4x64_epi64(packed, 0xD8));
    }
    return whole;
}

static void add_noise(uint8_t *out, const uint8_t *clean, const uint16_t *idx, int64_t n,
                      const Noise &z) {
    static const bool avx2 = __builtin_cpu_supports("avx2");
    int64_t done = 0;
    if (z.steps > 0)
        done = avx2 ? noise_count_avx2(out, clean, idx, n, z)
                    : noise_count_sse2(out, clean, idx, n, z);
    noise_lookup(out, clean, idx, done, n, z.block, z.sub);
}

// starts: (width, runs) int32, each column's run start rows ascending, the first 0 (a start
// equal to height begins no run). palette: (width * runs) packed RGBA, bytes r, g, b, a.
// noise: nullptr, or (height * width * 3) uint16 indices, one per byte of the image in
// row-major order, into the noise table, given in two levels that stay in the L1 cache:
// table[i] == sub[block[i >> 8] + (i & 255)], and as its steps (struct Noise; steps 0 when
// there are too many to count).
//
// A row differs from the one above only in the columns where a run starts, so the clean row
// is kept in `line` and patched at those columns (found through per-row buckets), then copied
// (or noised) into the image.
FR_EXPORT void fr_camera_paint(const int32_t *starts, int64_t runs, const uint32_t *palette,
                               int64_t width, int64_t height, uint8_t *rgb,
                               const uint16_t *noise, const int32_t *block, const int8_t *sub,
                               int64_t steps, const uint16_t *at, int64_t base,
                               uint64_t (*draw)(void *), void *draw_state) {
    const Noise z{noise, block, sub, steps <= MAX_STEPS ? steps : 0, at,
                  static_cast<int16_t>(base)};
    std::vector<int64_t> run(width, 0);  // each column's current run
    std::vector<uint8_t> line(3 * width);
    // draw: numpy's PCG64 itself (its next_raw), drawn here row by row, 3 * width / 4 raw
    // values a row (the caller makes sure that is whole), four indices each, low bits first:
    // random_raw(...).view(uint16) on this little-endian machine, without the array.
    std::vector<uint16_t> drawn(draw ? 3 * width : 0);
    // Columns by the rows where one of their runs starts (row 0 is painted whole).
    std::vector<int32_t> first(height + 1, 0), column;
    for (int64_t c = 0; c < width; ++c) {
        int32_t last = -1;  // a column is listed once per row (equal starts)
        for (int64_t j = 1; j < runs; ++j) {
            const int32_t s = starts[c * runs + j];
            if (s > 0 && s < height && s != last)
                ++first[s + 1];
            last = s;
        }
    }
    for (int64_t y = 0; y < height; ++y)
        first[y + 1] += first[y];
    column.resize(first[height]);
    {
        std::vector<int32_t> fill(first.begin(), first.end() - 1);
        for (int64_t c = 0; c < width; ++c) {
            int32_t last = -1;
            for (int64_t j = 1; j < runs; ++j) {
                const int32_t s = starts[c * runs + j];
                if (s > 0 && s < height && s != last)
                    column[fill[s]++] = static_cast<int32_t>(c);
                last = s;
            }
        }
    }
    auto paint = [&](int64_t c, int64_t y) {
        const int32_t *s = starts + c * runs;
        int64_t j = run[c];
        while (j + 1 < runs && s[j + 1] <= y)
            ++j;
        run[c] = j;
        std::memcpy(&line[3 * c], palette + c * runs + j, 3);  // r, g, b of r, g, b, a
    };
    for (int64_t y = 0; y < height; ++y) {
        if (y == 0) {
            for (int64_t c = 0; c < width; ++c)
                paint(c, 0);
        } else {
            for (int32_t i = first[y]; i < first[y + 1]; ++i)
                paint(column[i], y);
        }
        uint8_t *out = rgb + 3 * y * width;
        if (draw) {
            for (int64_t k = 0; k < 3 * width / 4; ++k) {
                const uint64_t bits = draw(draw_state);
                std::memcpy(&drawn[4 * k], &bits, 8);
            }
            add_noise(out, line.data(), drawn.data(), 3 * width, z);
        } else if (noise) {
            add_noise(out, line.data(), noise + 3 * y * width, 3 * width, z);
        } else {
            std::memcpy(out, line.data(), 3 * width);
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
                                   int64_t horizon, double ceil_r, double ceil_g,
                                   double ceil_b, double floor_r, double floor_g,
                                   double floor_b, int32_t *starts, uint32_t *palette) {
    const uint32_t ceil_rgba = packed(ceil_r, ceil_g, ceil_b);
    const uint32_t floor_rgba = packed(floor_r, floor_g, floor_b);
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
