// Verilator harness: adapts the verilated model (Vfollow_target) to the frame driver.
// Built plain and, only when a waveform is asked for, with FR_TRACE and FR_TRACE_FST (FST) or
// without it (VCD): the trace is dumped after every evaluation while tracing is enabled.
//
// One evaluation per clock cycle where possible: Verilator finds a rising edge by comparing
// clk with the value it saw at the previous eval(), which normally costs a second eval() at
// clk=0 (and this design's whole input-dependent logic runs in every eval()). When every
// output port is a flip-flop (FR_REGISTERED_OUTPUTS in fr_ports.h, found by the Python side)
// and this Verilator keeps that previous value in a member we can see, the harness holds clk
// high and clears the remembered value instead, so each eval() is one rising edge. Traced
// builds keep the real clock so that the waveform shows it.
#include <algorithm>
#include <cstring>
#include <memory>

#include "Vfollow_target.h"
#include "Vfollow_target___024root.h"
#include "fr_ports.h"
#include "frame_driver.h"
#include "verilated.h"
#include "verilator_clock.h"

// The design has no $display or DPI, so after the first eval() the harness calls the
// scheduler directly (verilator_clock.h; not in traced builds: the trace needs eval()'s
// bookkeeping). Define FR_VERILATOR_PUBLIC_EVAL to always use eval().

#ifdef FR_TRACE
#ifdef FR_TRACE_FST
#include "verilated_fst_c.h"
using TraceFile = VerilatedFstC;
#else
#include "verilated_vcd_c.h"
using TraceFile = VerilatedVcdC;
#endif
#endif

namespace {

using fr_verilator::forget_clk;

#if defined(FR_REGISTERED_OUTPUTS) && !defined(FR_TRACE)
constexpr bool ONE_EVAL = fr_verilator::remembers_clk<Vfollow_target___024root>::value;
#else
constexpr bool ONE_EVAL = false;
#endif

#ifdef FR_TRACE
struct TraceBase {};  // the tracing members are Sim's own
#else
using TraceBase = fr::Untraced;
#endif

struct Sim : TraceBase {
    static constexpr int evals_per_cycle = ONE_EVAL ? 1 : 2;
    std::unique_ptr<VerilatedContext> context;
    std::unique_ptr<Vfollow_target> top;

    Sim() : context(new VerilatedContext) {
#ifdef FR_TRACE
        context->traceEverOn(true);
#endif
        top.reset(new Vfollow_target(context.get(), "follow_target"));
        top->clk = 0;
        top->rst = 0;
        top->eval();
    }
    ~Sim() {
        trace_close();
        top->final();
    }

    inline void set_inputs(bool valid, uint16_t payload, uint8_t color_sel) {
        top->pixels___05Fvalid = valid;
        top->pixels___05Fpayload = payload;
        top->color_sel = color_sel;
    }
    // The model as when it was built: every register and memory at its initial value, which
    // a design without a reset needs. A traced model keeps its state (its waveform writer
    // holds the model; a traced backend is opened for one run).
    inline void restart() {
#ifndef FR_TRACE
        top->final();
        top.reset();
        top.reset(new Vfollow_target(context.get(), "follow_target"));
        top->clk = 0;
        top->rst = 0;
        top->eval();
#endif
    }
    inline void set_rst(bool on) { top->rst = on; }
    inline void eval() {
#if defined(FR_VERILATOR_PUBLIC_EVAL) || defined(FR_TRACE)  // tracing needs eval()'s bookkeeping
        top->eval();
#else
        Vfollow_target___024root___eval(top->rootp);
#endif
    }
    inline void settle(bool record = true) {
        if (ONE_EVAL)
            return;
        top->clk = 0;
        eval();
        if (record)
            sample();
    }
    inline void edge() {
        if (ONE_EVAL)
            forget_clk(top->rootp, std::integral_constant<bool, ONE_EVAL>());
        top->clk = 1;
        eval();
        sample();
    }
    inline bool filtered_valid() const { return top->filtered___05Fvalid; }
    inline uint16_t filtered_payload() const { return top->filtered___05Fpayload; }
    inline bool frame_done() const { return top->frame_done; }
    int64_t found() const { return top->found; }
    int64_t proximity() const { return top->proximity; }
    int64_t centroid_x() const { return top->centroid_x; }
    int64_t centroid_leds() const { return top->centroid_leds; }
    uint16_t motor_left() const { return top->motor_left; }
    uint16_t motor_right() const { return top->motor_right; }

#ifdef FR_TRACE
    static constexpr int traced = 1;
    std::unique_ptr<TraceFile> trace;
    bool enabled = false;
    uint64_t time = 0;  // half clock cycles since construction

    int trace_open(const char *path) {
        trace_close();
        trace.reset(new TraceFile);
        top->trace(trace.get(), 99);
        trace->open(path);
        return trace->isOpen() ? 0 : 1;
    }
    void trace_enable(int on) { enabled = on && trace; }
    void trace_close() {
        if (trace) {
            trace->close();
            trace.reset();
        }
        enabled = false;
    }
    inline void sample() {
        ++time;
        if (enabled)
            trace->dump(time);
    }
#endif
};

}  // namespace

FR_DEFINE_C_API(Sim)

#ifdef FR_WATCH
// [watch] (a foreign design's fr_ports.h defines FR_WATCH): the wrapper's fr_watch_any
// output, whatever Verilator's type for its width, as little-endian 32-bit words.
FR_EXPORT int fr_watch_read(void *h, uint32_t *out, int words) {
    const auto &port = static_cast<Sim *>(h)->top->fr_watch_any;
    const size_t room = static_cast<size_t>(words) * 4;
    std::memset(out, 0, room);
    std::memcpy(out, &port, std::min(sizeof(port), room));
    return static_cast<int>(std::min(sizeof(port), room));
}
#endif
