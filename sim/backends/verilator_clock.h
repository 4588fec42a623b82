// One rising edge per eval() of a verilated model (Vfollow_target), shared by the frame
// harness (verilator_harness.cpp) and the pin harness (sim/pins/pin_verilator.cpp).
//
// Verilator finds a rising edge by comparing clk with the value it saw at the previous
// eval(). When this Verilator keeps that value in a member we can see, a harness that holds
// clk high clears the member before each eval(), which then is one rising edge.
// Verilator's eval() also wraps the scheduler in per-call housekeeping (a mutex-guarded
// deleter, the message queue of $display and DPI) that costs more than a small design's
// whole cycle; for designs without either, after the first eval() (which runs the initial
// blocks) the harnesses call the scheduler, declared here, directly.
#ifndef FPGA_ROBOTICS_VERILATOR_CLOCK_H
#define FPGA_ROBOTICS_VERILATOR_CLOCK_H

#include <type_traits>
#include <utility>

class Vfollow_target___024root;
void Vfollow_target___024root___eval(Vfollow_target___024root *vlSelf);

namespace fr_verilator {

template <class R, class = void>
struct remembers_clk : std::false_type {};
template <class R>
struct remembers_clk<R, decltype(void(std::declval<R &>().__Vtrigprevexpr___TOP__clk__0))>
    : std::true_type {};

template <class R>
inline void forget_clk(R *root, std::true_type) { root->__Vtrigprevexpr___TOP__clk__0 = 0; }
template <class R>
inline void forget_clk(R *, std::false_type) {}

}  // namespace fr_verilator

#endif
