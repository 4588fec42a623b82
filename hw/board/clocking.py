"""Board clocking for the ULX3S: the ECP5 PLL that makes the design clock, and its reset.

The ULX3S has a 25 MHz oscillator. The published robot ran its logic at 50 MHz, so the board
top multiplies the oscillator by two with an ``EHXPLLL``. The design's ``sync`` domain is held in
reset while the PLL is not locked or while the reset button is pressed; at power-on the reset
synchroniser's flip-flops start asserted, so the design always sees a reset first.
"""

from dataclasses import dataclass

from amaranth.hdl import ClockSignal, Elaboratable, Instance, Module, Signal
from amaranth.lib.cdc import ResetSynchronizer

__all__ = ["ECP5PLL", "BoardClocking", "PLLParams", "ecp5_pll_params"]

# ECP5 EHXPLLL operating limits (Lattice TN1263 / FPGA-DS-02012, speed grade 6).
_VCO_MIN, _VCO_MAX = 400e6, 800e6
_PFD_MIN, _PFD_MAX = 3.125e6, 400e6
_OUT_MIN, _OUT_MAX = 3.125e6, 400e6


@dataclass(frozen=True)
class PLLParams:
    """Divider settings of one ``EHXPLLL`` using CLKOP as its own feedback."""

    clki_div: int
    clkfb_div: int
    clkop_div: int
    in_freq: float

    @property
    def out_freq(self):
        return self.in_freq / self.clki_div * self.clkfb_div

    @property
    def vco_freq(self):
        return self.out_freq * self.clkop_div

    @property
    def clkop_cphase(self):
        # Zero phase shift for the chosen output divider (the value ecppll writes).
        return (self.clkop_div - 1) // 2


def ecp5_pll_params(in_freq, out_freq):
    """Find exact ``EHXPLLL`` dividers for ``in_freq`` -> ``out_freq`` (Hz).

    Among the exact solutions, the one whose VCO is closest to 600 MHz (the middle of the
    range) is returned. Raises ``ValueError`` when no divider setting gives ``out_freq`` exactly.
    """
    if not _OUT_MIN <= out_freq <= _OUT_MAX:
        raise ValueError(f"PLL output {out_freq / 1e6:g} MHz is outside 3.125..400 MHz")
    best = None
    for clki_div in range(1, 129):
        pfd = in_freq / clki_div
        if not _PFD_MIN <= pfd <= _PFD_MAX:
            continue
        for clkfb_div in range(1, 81):
            if abs(pfd * clkfb_div - out_freq) > 1e-3:
                continue
            for clkop_div in range(1, 129):
                vco = out_freq * clkop_div
                if _VCO_MIN <= vco <= _VCO_MAX:
                    cand = PLLParams(clki_div, clkfb_div, clkop_div, in_freq)
                    if best is None or abs(vco - 600e6) < abs(best.vco_freq - 600e6):
                        best = cand
    if best is None:
        raise ValueError(
            f"no ECP5 PLL setting turns {in_freq / 1e6:g} MHz into exactly {out_freq / 1e6:g} MHz"
        )
    return best


class ECP5PLL(Elaboratable):
    """One ``EHXPLLL`` primitive: ``clk_in`` -> ``clk_out`` with a ``locked`` flag.

    Parameters
    ----------
    params : PLLParams
        Divider settings, from :func:`ecp5_pll_params`.
    """

    def __init__(self, params):
        self.params = params
        self.clk_in = Signal()
        self.clk_out = Signal()
        self.locked = Signal()

    def elaborate(self, platform):
        p = self.params
        m = Module()
        m.submodules.pll = Instance(
            "EHXPLLL",
            a_FREQUENCY_PIN_CLKI=f"{p.in_freq / 1e6:g}",
            a_FREQUENCY_PIN_CLKOP=f"{p.out_freq / 1e6:g}",
            a_ICP_CURRENT="12",
            a_LPF_RESISTOR="8",
            a_MFG_ENABLE_FILTEROPAMP="1",
            a_MFG_GMCREF_SEL="2",
            p_PLLRST_ENA="DISABLED",
            p_INTFB_WAKE="DISABLED",
            p_STDBY_ENABLE="DISABLED",
            p_DPHASE_SOURCE="DISABLED",
            p_OUTDIVIDER_MUXA="DIVA",
            p_OUTDIVIDER_MUXB="DIVB",
            p_OUTDIVIDER_MUXC="DIVC",
            p_OUTDIVIDER_MUXD="DIVD",
            p_CLKI_DIV=p.clki_div,
            p_CLKOP_ENABLE="ENABLED",
            p_CLKOP_DIV=p.clkop_div,
            p_CLKOP_CPHASE=p.clkop_cphase,
            p_CLKOP_FPHASE=0,
            p_FEEDBK_PATH="CLKOP",
            p_CLKFB_DIV=p.clkfb_div,
            i_RST=0,
            i_STDBY=0,
            i_CLKI=self.clk_in,
            o_CLKOP=self.clk_out,
            i_CLKFB=self.clk_out,
            i_PHASESEL0=0,
            i_PHASESEL1=0,
            i_PHASEDIR=1,
            i_PHASESTEP=1,
            i_PHASELOADREG=1,
            i_PLLWAKESYNC=0,
            i_ENCLKOP=0,
            o_LOCK=self.locked,
        )
        return m


class BoardClocking(Elaboratable):
    """Drives the clock and reset of the ``sync`` domain (defined by the parent) at
    ``sys_clk_freq`` from the board oscillator.

    Parameters
    ----------
    clk_in : Signal
        The oscillator input (already through its input buffer).
    reset_in : Signal
        Active-high reset request (the reset button), asynchronous to everything.
    in_freq, sys_clk_freq : float
        Oscillator and design clock frequencies in Hz. When they are equal no PLL is used.
    """

    def __init__(self, clk_in, reset_in, *, in_freq, sys_clk_freq):
        self.clk_in = clk_in
        self.reset_in = reset_in
        self.in_freq = in_freq
        self.sys_clk_freq = sys_clk_freq
        self.pll_params = (
            None if in_freq == sys_clk_freq else ecp5_pll_params(in_freq, sys_clk_freq)
        )

    def elaborate(self, platform):
        m = Module()
        locked = Signal()
        if self.pll_params is None:
            m.d.comb += [ClockSignal("sync").eq(self.clk_in), locked.eq(1)]
        else:
            m.submodules.pll = pll = ECP5PLL(self.pll_params)
            m.d.comb += [
                pll.clk_in.eq(self.clk_in),
                ClockSignal("sync").eq(pll.clk_out),
                locked.eq(pll.locked),
            ]
            if platform is not None:  # the requirement nextpnr checks the design clock against
                platform.add_clock_constraint(pll.clk_out, self.sys_clk_freq)
        m.submodules.reset_sync = ResetSynchronizer(self.reset_in | ~locked, domain="sync")
        return m
