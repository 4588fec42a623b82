// Pin driver shared by the compiled pin backends: the clock loop of `run()` runs here, so
// Python makes one call per run. The cycle numbering is sim/pins/base.py's:
//   state c = after rising edge c, with the inputs of edge c + 1 applied and settled.
//   run(n): for each edge e = c + 1 .. c + n: capture the filtered beat that edge samples;
//   the edge; then the inputs due at e + 1 (scheduled changes, the pixel slot); settle;
//   compare the watched outputs with the values last reported; stop at a difference.
//
// The idle edge costs the model's evaluation, one compare against the next event edge (the
// earlier of the next scheduled change and the next pixel-stream change), one read of the
// filtered valid bit (when the design has a filtered stream) and the masked compare of the
// outputs (pin_diff, generated per design).
//
// A simulator adapter `S` (pin_cxxrtl.cpp, pin_verilator.cpp) provides:
//   evals_per_cycle, set_rst(bool), edge() (one rising edge), settle() (evaluate the
//   combinational logic with the inputs now; nothing to do when every output is a
//   flip-flop), stop_pending() (the design called $finish, $stop or $fatal: the run ends
//   there with status STOPPED) and stop_message(), restart(), and `top`, the model that the
//   generated pin_design.h functions take:
//   pin_set_input(top, i, v), pin_get(top, i), pin_zero_inputs(top),
//   pin_diff(top, mask, prev), pin_set_pixel(top, valid, payload),
//   pin_filtered_valid(top), pin_filtered_payload(top), and PIN_HAS_PIXELS,
//   PIN_HAS_FILTERED.
#ifndef FPGA_ROBOTICS_PIN_DRIVER_H
#define FPGA_ROBOTICS_PIN_DRIVER_H

#include <algorithm>
#include <cstdint>
#include <vector>

#define PIN_EXPORT extern "C" __attribute__((visibility("default")))

namespace pin {

// Bump when an entry point or the result layout changes (checked by the Python side).
constexpr int ABI_VERSION = 3;

enum Out { O_CYCLE, O_PORT, O_VALUE, O_CAPTURED, O_PENDING, O_BAD_INDEX, O_RECORDED, O_COUNT };
enum Status { OK = 0, TOO_MANY_FILTERED = 1, BAD_FILTERED_FLAGS = 2, BAD_ARGUMENTS = 3,
              CAPTURES_FULL = 4, STOPPED = 5 };

constexpr int64_t NEVER = INT64_MAX;
constexpr uint16_t FIRST = 1u << 12, LAST = 1u << 13, PIXEL = 0x0FFF;

struct Change {
    int64_t edge;
    int port;
    uint64_t value;
};

template <class S>
struct Driver {
    S sim;
    int64_t cycle = 0;
    // Scheduled changes, sorted by edge (stable), consumed from `head`.
    std::vector<Change> queue;
    size_t head = 0;
    int64_t next_due = NEVER;
    // The pixel stream: the next pixel (py, px) and its edge; `shown` while valid is high.
    std::vector<uint16_t> frame;
    int64_t width = 0, height = 0, start = 0, line_period = 0, pixel_period = 1;
    int64_t py = 0, px = 0, next_pixel = NEVER, valid_off = NEVER, last_pixel_edge = 0;
    // The earliest of next_due, next_pixel and valid_off: the one compare of an idle edge.
    int64_t next_event = NEVER;
    // Filtered capture: up to two frames' buffers (a frame's tail may still be coming out
    // when the next frame is queued), filled in order.
    uint16_t *captures[2] = {nullptr, nullptr};
    int n_captures = 0;
    int64_t captured = 0, frames_captured = 0, capture_size = 0, bad_index = -1;
    // Watched outputs: mask by port index, order for ties, values last reported.
    uint64_t mask = 0;
    std::vector<int> order;
    uint64_t prev[64] = {};

    Driver() { reset(); }

    void reset() {
        // From the power-on state: what the reset does not reach (a register without one, a
        // memory) must not carry over from an earlier run.
        sim.restart();
        pin_zero_inputs(sim.top);
        sim.set_rst(true);
        sim.settle();
        sim.edge();
        sim.set_rst(false);
        cycle = 0;
        queue.clear();
        head = 0;
        next_due = next_pixel = valid_off = next_event = NEVER;
        last_pixel_edge = 0;
        frame.clear();
        n_captures = 0;
        captured = frames_captured = 0;
        bad_index = -1;
        mask = 0;
        order.clear();
        sim.settle();
        sim.stop_pending();  // a call in the reset is this model's: noted now
    }

    void update_next_event() { next_event = std::min(next_due, std::min(next_pixel, valid_off)); }

    // Inputs given for edge `e`: scheduled changes in order, then the pixel slot.
    void apply_events(int64_t e) {
        while (next_due == e) {
            const Change &c = queue[head++];
            pin_set_input(sim.top, c.port, c.value);
            next_due = head < queue.size() ? queue[head].edge : NEVER;
        }
        if (head == queue.size()) {
            queue.clear();
            head = 0;
        } else if (head >= 64 && 2 * head >= queue.size()) {
            // Changes scheduled far ahead keep the queue from emptying: drop the used part.
            queue.erase(queue.begin(), queue.begin() + head);
            head = 0;
        }
#if PIN_HAS_PIXELS
        if (next_pixel == e) {
            uint16_t payload = frame[py * width + px] & PIXEL;
            if (py == 0 && px == 0)
                payload |= FIRST;
            if (px == width - 1)
                payload |= LAST;
            pin_set_pixel(sim.top, true, payload);
            valid_off = e + 1;
            if (++px == width) {
                px = 0;
                ++py;
            }
            next_pixel = py == height ? NEVER : start + py * line_period + px * pixel_period;
        } else if (valid_off == e) {
            pin_set_pixel(sim.top, false, 0);
            valid_off = NEVER;
        }
#endif
        update_next_event();
    }

    // Host-side change for edge cycle + 1: applied now (that edge's inputs are on already).
    void host_changed() {
        if (next_event == cycle + 1)
            apply_events(cycle + 1);
        sim.settle();
        sim.stop_pending();  // a call in this evaluation is this model's: noted now
    }

    void poke(int port, uint64_t value) {
        pin_set_input(sim.top, port, value);
        sim.settle();
        sim.stop_pending();
    }

    void schedule(int64_t edge, int port, uint64_t value) {
        if (edge == cycle + 1) {
            poke(port, value);
            return;
        }
        Change c{edge, port, value};
        auto at = std::upper_bound(queue.begin() + head, queue.end(), c,
                                   [](const Change &a, const Change &b) { return a.edge < b.edge; });
        queue.insert(at, c);
        next_due = queue[head].edge;
        update_next_event();
    }

    // Many changes of one input, their edges increasing and after `cycle + 1`: merged
    // into the queue at once (a frame's pixels, a unit judge's stimulus).
    void schedule_many(int port, const int64_t *edges, const uint64_t *values, int64_t n) {
        if (n <= 0)
            return;
        const size_t old_size = queue.size();
        queue.reserve(old_size + n);
        for (int64_t k = 0; k < n; ++k)
            queue.push_back(Change{edges[k], port, values[k]});
        // Stable: a change already queued for an edge stays before the new ones of it.
        std::inplace_merge(queue.begin() + head, queue.begin() + old_size, queue.end(),
                           [](const Change &a, const Change &b) { return a.edge < b.edge; });
        next_due = queue[head].edge;
        update_next_event();
    }

    void watch(const int32_t *ports, int64_t n) {
        mask = 0;
        order.assign(ports, ports + n);
        for (int p : order) {
            mask |= uint64_t(1) << p;
            prev[p] = pin_get(sim.top, p);
        }
    }

    int stream(const uint16_t *pixels, const int64_t *geometry, uint16_t *capture) {
        // geometry: width, height, start, line_period, pixel_period
        if (!PIN_HAS_PIXELS || last_pixel_edge > cycle || geometry[2] <= cycle)
            return BAD_ARGUMENTS;
        if (capture && n_captures == 2)
            return CAPTURES_FULL;
        width = geometry[0];
        height = geometry[1];
        start = geometry[2];
        line_period = geometry[3];
        pixel_period = geometry[4];
        frame.assign(pixels, pixels + width * height);
        py = px = 0;
        next_pixel = start;
        last_pixel_edge = start + (height - 1) * line_period + (width - 1) * pixel_period;
        if (capture) {
            captures[n_captures++] = capture;
            capture_size = width * height;
        }
        update_next_event();
        host_changed();
        return OK;
    }

    // One filtered beat; false on a framing error.
    bool capture() {
        if (n_captures == 0)
            return false;
        uint16_t p = pin_filtered_payload(sim.top);
        int64_t x = captured % width;
        uint16_t expect = (captured == 0 ? FIRST : 0) | (x == width - 1 ? LAST : 0);
        if ((p & (FIRST | LAST)) != expect) {
            bad_index = captured;
            return false;
        }
        captures[0][captured++] = p & PIXEL;
        if (captured == capture_size) {
            captures[0] = captures[1];
            --n_captures;
            captured = 0;
            ++frames_captured;
        }
        return true;
    }

    int run(int64_t n, int64_t *out) {
        const int64_t end = cycle + n;
        int status = OK;
        uint64_t diff = pin_diff(sim.top, mask, prev);
        // A design that stopped (here or on an earlier host call) runs no further edge.
        if (__builtin_expect(sim.stop_pending(), 0))
            status = STOPPED;
        while (status == OK && !diff && cycle < end) {
#if PIN_HAS_FILTERED
            // The beat the coming edge samples, as a consumer of the stream sees it.
            if (__builtin_expect(pin_filtered_valid(sim.top), 0) && !capture()) {
                status = n_captures == 0 ? TOO_MANY_FILTERED : BAD_FILTERED_FLAGS;
                break;
            }
#endif
            sim.edge();
            const int64_t next = ++cycle + 1;
            if (__builtin_expect(next_event == next, 0))
                apply_events(next);
            sim.settle();
            if (__builtin_expect(sim.stop_pending(), 0)) {
                status = STOPPED;  // at this edge: its outputs are not compared
                break;
            }
            diff = pin_diff(sim.top, mask, prev);
        }
        out[O_PORT] = -1;
        out[O_VALUE] = 0;
        if (diff) {
            for (int p : order) {
                if (diff >> p & 1) {
                    prev[p] = pin_get(sim.top, p);
                    out[O_PORT] = p;
                    out[O_VALUE] = static_cast<int64_t>(prev[p]);
                    break;
                }
            }
        }
        out[O_CYCLE] = cycle;
        out[O_CAPTURED] = frames_captured;
        out[O_PENDING] = last_pixel_edge > cycle;
        out[O_BAD_INDEX] = bad_index;
        return status;
    }

    // `run` again and again over `n` edges, each watched change written to `changes` as
    // (cycle, port, value), up to `cap` of them; out[O_RECORDED] says how many. Ends early
    // (out[O_PORT] >= 0) when `cap` is reached or a run fails (its status returned).
    int record(int64_t n, int64_t *changes, int64_t cap, int64_t *out) {
        const int64_t end = cycle + n;
        int64_t k = 0;
        int status = OK;
        out[O_PORT] = -1;
        while (k < cap) {
            status = run(end - cycle, out);
            if (status != OK || out[O_PORT] < 0)
                break;
            changes[3 * k] = out[O_CYCLE];
            changes[3 * k + 1] = out[O_PORT];
            changes[3 * k + 2] = out[O_VALUE];
            ++k;
        }
        out[O_RECORDED] = k;
        return status;
    }
};

}  // namespace pin

// The C entry points of a pin harness, given its adapter type `SIM`.
#define PIN_DEFINE_C_API(SIM)                                                                 \
    using PinDriver = pin::Driver<SIM>;                                                       \
    PIN_EXPORT int pin_abi_version() { return pin::ABI_VERSION; }                             \
    PIN_EXPORT int pin_evals_per_cycle() { return SIM::evals_per_cycle; }                     \
    PIN_EXPORT void *pin_create() { return new PinDriver(); }                                 \
    PIN_EXPORT void pin_destroy(void *h) { delete static_cast<PinDriver *>(h); }              \
    PIN_EXPORT void pin_reset(void *h) { static_cast<PinDriver *>(h)->reset(); }              \
    PIN_EXPORT int64_t pin_cycle(void *h) { return static_cast<PinDriver *>(h)->cycle; }      \
    PIN_EXPORT void pin_poke(void *h, int port, uint64_t value) {                             \
        static_cast<PinDriver *>(h)->poke(port, value);                                       \
    }                                                                                         \
    PIN_EXPORT uint64_t pin_peek(void *h, int port) {                                         \
        return pin_get(static_cast<PinDriver *>(h)->sim.top, port);                           \
    }                                                                                         \
    PIN_EXPORT void pin_schedule(void *h, int64_t edge, int port, uint64_t value) {           \
        static_cast<PinDriver *>(h)->schedule(edge, port, value);                             \
    }                                                                                         \
    PIN_EXPORT void pin_schedule_many(void *h, int port, const int64_t *edges,                \
                                      const uint64_t *values, int64_t n) {                    \
        static_cast<PinDriver *>(h)->schedule_many(port, edges, values, n);                   \
    }                                                                                         \
    PIN_EXPORT int pin_record(void *h, int64_t n, int64_t *changes, int64_t cap,              \
                              int64_t *out) {                                                 \
        return static_cast<PinDriver *>(h)->record(n, changes, cap, out);                     \
    }                                                                                         \
    PIN_EXPORT void pin_watch(void *h, const int32_t *ports, int64_t n) {                     \
        static_cast<PinDriver *>(h)->watch(ports, n);                                         \
    }                                                                                         \
    PIN_EXPORT int pin_stream(void *h, const uint16_t *pixels, const int64_t *geometry,       \
                              uint16_t *capture) {                                            \
        return static_cast<PinDriver *>(h)->stream(pixels, geometry, capture);                \
    }                                                                                         \
    PIN_EXPORT int pin_run(void *h, int64_t n, int64_t *out) {                                \
        return static_cast<PinDriver *>(h)->run(n, out);                                      \
    }                                                                                         \
    PIN_EXPORT const char *pin_stop_message(void *h) {                                        \
        return static_cast<PinDriver *>(h)->sim.stop_message();                               \
    }

#endif
