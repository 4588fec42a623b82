// Verilator harness: adapts the verilated model (Vfollow_target) to the frame driver.
// Built plain and, only when a waveform is asked for, with FR_TRACE and FR_TRACE_FST (FST) or
// without it (VCD): the trace is dumped after every evaluation while tracing is enabled.
#include <memory>

#include "Vfollow_target.h"
#include "frame_driver.h"
#include "verilated.h"

// Verilator's eval() wraps the scheduler in per-call housekeeping (a mutex-guarded deleter,
// the message queue of $display and DPI) that costs more than this design's whole cycle.
// The design has neither, so after the first eval() (which runs the initial blocks) the
// harness calls the scheduler directly. Define FR_VERILATOR_PUBLIC_EVAL to use eval().
class Vfollow_target___024root;
void Vfollow_target___024root___eval(Vfollow_target___024root *vlSelf);

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

struct Sim {
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
    inline void set_rst(bool on) { top->rst = on; }
    inline void eval() {
#ifdef FR_VERILATOR_PUBLIC_EVAL
        top->eval();
#else
        Vfollow_target___024root___eval(top->rootp);
#endif
    }
    inline void settle() {
        top->clk = 0;
        eval();
        sample();
    }
    inline void edge() {
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
#else
    static constexpr int traced = 0;
    int trace_open(const char *) { return 2; }
    void trace_enable(int) {}
    void trace_close() {}
    inline void sample() {}
#endif
};

}  // namespace

FR_DEFINE_C_API(Sim)
