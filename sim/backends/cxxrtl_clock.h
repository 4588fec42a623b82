// Clocking a CXXRTL model (class with p_clk, prev_p_clk, eval(), commit(), step()), shared by
// the frame harness (cxxrtl_harness.cpp) and the pin harness (sim/pins/pin_cxxrtl.cpp).
//
// One evaluation per cycle (when every output is read from flip-flops, FR_REGISTERED_OUTPUTS):
// the clock is held high and the remembered previous clock low, so every eval() is a rising
// edge; the edge is committed by copying the wires' next values (FR_COMMIT, generated from
// the model's commit()) or by commit(), after which the remembered clock is set low again.
// Two evaluations per cycle otherwise: step() with the clock high (the edge) and low (the
// combinational outputs settle on the inputs now).
#ifndef FPGA_ROBOTICS_CXXRTL_CLOCK_H
#define FPGA_ROBOTICS_CXXRTL_CLOCK_H

namespace fr_cxxrtl {

template <class Top>
inline void one_eval_init(Top &top) {
    top.p_clk.template set<bool>(true);
    top.prev_p_clk.template set<bool>(false);
}

template <class Top>
inline void one_eval_edge(Top &top) {
    top.eval();
#ifdef FR_COMMIT
    FR_COMMIT(top);
#else
    top.commit();
    top.prev_p_clk.template set<bool>(false);  // commit() recorded the high clock: the next edge
#endif
}

template <class Top>
inline void step_edge(Top &top) {
    top.p_clk.template set<bool>(true);
    top.step();
}

template <class Top>
inline void step_settle(Top &top) {
    top.p_clk.template set<bool>(false);
    top.step();
}

}  // namespace fr_cxxrtl

#endif
