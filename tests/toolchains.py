"""Skip markers for tests that need tools the machine may lack."""

import pytest

__all__ = ["needs_mutation_toolchain"]


def mutation_toolchain_missing():
    """Why Yosys's mutate pass and a Verilator build cannot run here, or None."""
    from fpga_robotics.sim import mutation
    from fpga_robotics.sim.backends import BackendError
    from fpga_robotics.sim.backends import toolchain as tc

    try:
        mutation.find_yosys()
        tc.find_compiler(), tc.find_make(), tc.verilator_root()
    except (mutation.MutationError, BackendError) as exc:  # pragma: no cover - the machine
        return str(exc)
    return None


#: Marks a test that builds a mutant netlist's Verilator model.
needs_mutation_toolchain = pytest.mark.skipif(
    mutation_toolchain_missing() is not None, reason="no Yosys or Verilator toolchain"
)
