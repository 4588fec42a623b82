// Frame driver shared by the compiled backends: the whole clock loop of one frame runs here,
// so Python makes one call per frame. The cycle accounting is the one of
// sim/backends/base.py and docs/backends.md:
//   edges are numbered 1.. within a call; line y's pixels are sampled at edges
//   y*(W+lb)+1 .. y*(W+lb)+W, then lb idle edges; the last pixel is sampled at edge
//   P = H*(W+lb) - lb. The driver sees frame_done itself (first edge D >= P after which it is
//   high) and stops after max(H*(W+lb) + frame_blank, D + motor_latency) edges.
//
// A simulator adapter `S` provides:
//   set_inputs(valid, payload, color_sel), set_rst(bool)
//   settle()   clock low, evaluate: outputs show the state after the last edge and the
//              combinational response to the inputs that the next edge samples
//   settle(false)  the same, not recorded in a waveform (sample() records it later)
//   sample()   record the half cycle in a waveform (traced builds; nothing otherwise)
//   edge()     clock high, evaluate: one rising edge
//   filtered_valid(), filtered_payload(), frame_done(), and the result outputs.
//
// Frames come packed (RGB444 in uint16, fr_run_frame) or as the host's RGB888 image
// (H x W x 3 uint8, row-major, fr_run_frame_rgb888): the loop packs each pixel as it streams
// it in (a channel keeps its top 4 bits, sim/frames.py), so the host makes no copy. The
// loop's own time is returned in out[O_LOOP_NS], for the benchmark's Python-side figure.
#ifndef FPGA_ROBOTICS_FRAME_DRIVER_H
#define FPGA_ROBOTICS_FRAME_DRIVER_H

#include <chrono>
#include <cstdint>

#define FR_EXPORT extern "C" __attribute__((visibility("default")))

namespace fr {

// Bump when the argument or result layout changes (checked by the Python side).
constexpr int ABI_VERSION = 2;

enum Arg { A_WIDTH, A_HEIGHT, A_COLOR_SEL, A_LINE_BLANK, A_FRAME_BLANK, A_MOTOR_LATENCY,
           A_WATCHDOG, A_COUNT };
enum Out { O_CYCLES, O_FOUND, O_PROXIMITY, O_CENTROID_X, O_CENTROID_LEDS, O_MOTOR_LEFT,
           O_MOTOR_RIGHT, O_FILTERED, O_DONE_EDGE, O_BAD_INDEX, O_LOOP_NS, O_COUNT };
enum Status { OK = 0, NO_FRAME_DONE = 1, TOO_MANY_FILTERED = 2, TOO_FEW_FILTERED = 3,
              BAD_FILTERED_FLAGS = 4, BAD_ARGUMENTS = 5 };

constexpr uint16_t FIRST = 1u << 12, LAST = 1u << 13, PIXEL = 0x0FFF;

// Pixel sources: the 12-bit pixel x of row y.
struct Packed {
    const uint16_t *frame;
    int64_t width;
    inline uint16_t operator()(int64_t y, int64_t x) const { return frame[y * width + x] & PIXEL; }
};
struct Rgb888 {
    const uint8_t *rgb;
    int64_t width;
    inline uint16_t operator()(int64_t y, int64_t x) const {
        const uint8_t *p = rgb + 3 * (y * width + x);
        return static_cast<uint16_t>(((p[0] & 0xF0u) << 4) | (p[1] & 0xF0u) | (p[2] >> 4));
    }
};

template <class S>
class FrameRun {
public:
    FrameRun(S &sim, const int64_t *args, uint16_t *filtered)
        : sim(sim), width(args[A_WIDTH]), height(args[A_HEIGHT]),
          color_sel(static_cast<uint8_t>(args[A_COLOR_SEL])), filtered(filtered),
          capacity(args[A_WIDTH] * args[A_HEIGHT]) {}

    // One clock cycle: present the inputs, settle, observe, then the rising edge.
    inline void cycle(bool valid, uint16_t payload) {
        sim.set_inputs(valid, payload, color_sel);
        sim.settle();
        observe();
        sim.edge();
        ++edges;
    }

    inline void observe() {
        if (done_edge < 0 && edges >= last_pixel_edge && sim.frame_done())
            done_edge = edges;
        if (sim.filtered_valid()) {
            if (n_filtered >= capacity) {
                status = status ? status : TOO_MANY_FILTERED;
                return;
            }
            uint16_t p = sim.filtered_payload();
            int64_t x = n_filtered % width;
            uint16_t expect = (n_filtered == 0 ? FIRST : 0) | (x == width - 1 ? LAST : 0);
            if ((p & (FIRST | LAST)) != expect && status == OK) {
                status = BAD_FILTERED_FLAGS;
                bad_index = n_filtered;
            }
            filtered[n_filtered++] = p & PIXEL;
        }
    }

    template <class Source>
    int run(const Source &pixel, int64_t line_blank, int64_t frame_blank,
            int64_t motor_latency, int64_t watchdog, int64_t *out) {
        const int64_t pixel_edges = height * (width + line_blank);
        const int64_t min_edges = pixel_edges + frame_blank;
        last_pixel_edge = pixel_edges - line_blank;
        for (int64_t y = 0; y < height; ++y) {
            uint16_t first = y == 0 ? FIRST : 0;
            cycle(true, pixel(y, 0) | first | (width == 1 ? LAST : 0));
            for (int64_t x = 1; x < width - 1; ++x)
                cycle(true, pixel(y, x));
            if (width > 1)
                cycle(true, pixel(y, width - 1) | LAST);
            for (int64_t i = 0; i < line_blank; ++i)
                cycle(false, 0);
        }
        // Idle until frame_blank has passed and the motors show the frame's values. The
        // settle that ends the frame is not a half cycle of its own in a waveform: the next
        // frame's (or reset's) first settle is the same one, with its inputs.
        for (;;) {
            sim.set_inputs(false, 0, color_sel);
            sim.settle(false);
            if (done_edge < 0 && edges >= last_pixel_edge && sim.frame_done())
                done_edge = edges;
            if (done_edge >= 0 && edges >= min_edges && edges >= done_edge + motor_latency)
                break;
            if (edges >= watchdog) {
                status = NO_FRAME_DONE;
                break;
            }
            sim.sample();
            observe();
            sim.edge();
            ++edges;
        }
        if (status == OK && n_filtered < capacity)
            status = TOO_FEW_FILTERED;
        out[O_CYCLES] = edges;
        out[O_FOUND] = sim.found();
        out[O_PROXIMITY] = sim.proximity();
        out[O_CENTROID_X] = sim.centroid_x();
        out[O_CENTROID_LEDS] = sim.centroid_leds();
        out[O_MOTOR_LEFT] = static_cast<int16_t>(sim.motor_left());
        out[O_MOTOR_RIGHT] = static_cast<int16_t>(sim.motor_right());
        out[O_FILTERED] = n_filtered;
        out[O_DONE_EDGE] = done_edge;
        out[O_BAD_INDEX] = bad_index;
        return status;
    }

private:
    S &sim;
    const int64_t width, height;
    const uint8_t color_sel;
    uint16_t *filtered;
    const int64_t capacity;
    int64_t edges = 0, done_edge = -1, n_filtered = 0, bad_index = -1, last_pixel_edge = 0;
    int status = OK;
};

template <class S, class Source>
int run_frame(S &sim, const Source &pixel, const int64_t *args, uint16_t *filtered,
              int64_t *out) {
    if (args[A_WIDTH] < 1 || args[A_HEIGHT] < 1 || args[A_LINE_BLANK] < 0 ||
        args[A_FRAME_BLANK] < 0 || args[A_MOTOR_LATENCY] < 0)
        return BAD_ARGUMENTS;
    const auto start = std::chrono::steady_clock::now();
    FrameRun<S> run(sim, args, filtered);
    int status = run.run(pixel, args[A_LINE_BLANK], args[A_FRAME_BLANK],
                         args[A_MOTOR_LATENCY], args[A_WATCHDOG], out);
    out[O_LOOP_NS] = std::chrono::duration_cast<std::chrono::nanoseconds>(
                         std::chrono::steady_clock::now() - start).count();
    return status;
}

// From the power-on state (what the reset does not reach, a register without one or a
// memory, must not carry over from an earlier run), then a synchronous reset: rst high for
// one rising edge, not counted in any frame.
template <class S>
void reset(S &sim) {
    sim.restart();
    sim.set_inputs(false, 0, 0);
    sim.set_rst(true);
    sim.settle();
    sim.edge();
    sim.set_rst(false);
}

// The tracing members of an adapter built without FR_TRACE (its base then): no waveform
// writer; trace_open() answers 2, "this build does not trace".
struct Untraced {
    static constexpr int traced = 0;
    int trace_open(const char *) { return 2; }
    void trace_enable(int) {}
    void trace_close() {}
    inline void sample() {}
};

}  // namespace fr

// The C entry points every harness exports, given its adapter type `SIM`.
#define FR_DEFINE_C_API(SIM)                                                                  \
    FR_EXPORT int fr_abi_version() { return fr::ABI_VERSION; }                                \
    FR_EXPORT int fr_traced() { return SIM::traced; }                                         \
    FR_EXPORT int fr_evals_per_cycle() { return SIM::evals_per_cycle; }                       \
    FR_EXPORT void *fr_create() { return new SIM(); }                                         \
    FR_EXPORT void fr_destroy(void *h) { delete static_cast<SIM *>(h); }                      \
    FR_EXPORT void fr_reset(void *h) { fr::reset(*static_cast<SIM *>(h)); }                   \
    FR_EXPORT int fr_trace_open(void *h, const char *path) {                                  \
        return static_cast<SIM *>(h)->trace_open(path);                                       \
    }                                                                                         \
    FR_EXPORT void fr_trace_enable(void *h, int on) { static_cast<SIM *>(h)->trace_enable(on); } \
    FR_EXPORT void fr_trace_close(void *h) { static_cast<SIM *>(h)->trace_close(); }          \
    FR_EXPORT int fr_run_frame(void *h, const uint16_t *frame, const int64_t *args,           \
                               uint16_t *filtered, int64_t *out) {                            \
        return fr::run_frame(*static_cast<SIM *>(h), fr::Packed{frame, args[fr::A_WIDTH]},   \
                             args, filtered, out);                                            \
    }                                                                                         \
    FR_EXPORT int fr_run_frame_rgb888(void *h, const uint8_t *rgb, const int64_t *args,       \
                                      uint16_t *filtered, int64_t *out) {                     \
        return fr::run_frame(*static_cast<SIM *>(h), fr::Rgb888{rgb, args[fr::A_WIDTH]},      \
                             args, filtered, out);                                            \
    }

#endif
