// Verilator's own fatal errors, for a model built with VL_USER_FATAL: one line and exit code
// 2, as the command line's errors are, rather than Verilator's "%Error ... Aborting..." and
// exit code 1. Included by exactly one translation unit of each harness (the frame harness's
// hooks, the pin harness). A settle region that does not converge is a combinational loop
// that no model settles.
#pragma once
#include <cstdio>
#include <cstdlib>
#include <cstring>

void vl_fatal(const char *, int, const char *, const char *msg) {
    const bool loop = std::strstr(msg, "converge") != nullptr;
    std::fflush(stdout);
    std::fprintf(stderr, "fpga-robotics: error: the design stopped in Verilator: %s%s\n", msg,
                 loop ? ": a combinational loop (logic that feeds its own input without a "
                        "flip-flop) never settles; break the loop with a register "
                        "(always @(posedge clk))"
                      : "");
    std::fflush(stderr);
    std::_Exit(2);
}
