// The camera renderer's per-pixel stage (sim/camera.py, loaded by sim/camera_pixels.py): paint
// every column's runs of rows with their colours straight into the RGB888 image, and add the
// sensor noise in the same pass. Integer work only, the same as the numpy path it replaces
// (run ids by cumulative sum, palette lookup, RGBA to RGB, table lookup, saturating add), so
// the two give the same bytes.
#include <cstdint>
#include <cstring>
#include <vector>

#define FR_EXPORT extern "C" __attribute__((visibility("default")))

FR_EXPORT int fr_camera_pixels_version() { return 1; }

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
