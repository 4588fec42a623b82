"""Where the OV7670 camera and the GoPiGo3 SPI bus are wired on the ULX3S: one place, one table.

The sites are the published pin assignment of the FPGA-Robotics GoPiGo3 robot
(``ulx3s_v20.lpf`` of the published board project, see ``docs/board.md``). The camera sits on
the ULX3S GPIO header J1 (``gpio`` connector pairs 0..5 and 13), the GoPiGo3 SPI bus on pairs 6
and 20, the camera reset on pair 21.

=========  ======  ================  =====  ===============================================
signal     site    ULX3S connector   dir    note
=========  ======  ================  =====  ===============================================
d[0]       B11     gpio 0+           in     camera data, bit 0
d[1]       C11     gpio 0-           in
d[2]       A10     gpio 1+           in
d[3]       A11     gpio 1-           in
d[4]       A9      gpio 2+           in
d[5]       B10     gpio 2-           in
d[6]       B9      gpio 3+           in
d[7]       C10     gpio 3-           in     camera data, bit 7
xclk       A7      gpio 4+           out    camera master clock, 12.5 MHz
pclk       A8      gpio 4-           in     camera pixel (byte) clock
href       C8      gpio 5+           in     high while a line's bytes are output
vsync      B8      gpio 5-           in     high between frames
siod       H4      gpio 13+          inout  SCCB data (released on the don't-care bit)
sioc       G5      gpio 13-          out    SCCB clock
reset_n    C18     gpio 21+          out    camera reset, active low: driven high
ss_n       C6      gpio 6+           out    GoPiGo3 SPI chip select, active low
sclk       C7      gpio 6-           out    GoPiGo3 SPI clock, mode 0, ~500 kHz
miso       D18     gpio 20+          in     GoPiGo3 SPI data in (unused: write-only)
mosi       E17     gpio 20-          out    GoPiGo3 SPI data out
=========  ======  ================  =====  ===============================================

The camera's PWDN pin is not wired in the published assignment: tie it low (most OV7670
modules pull it down already). Every pin is LVCMOS33.

A second, pan camera (a design with ``turret_pixels``, the turret application) has no
published assignment; ``TURRET_CAMERA_PINS`` puts it on header pairs 22-27 and 19, pins the
board's own wiring leaves free, with its reset wired to the first camera's (one pin drives
both).
"""

from amaranth.build import Attrs, Clock, Pins, PinsN, Resource, Subsignal

__all__ = [
    "CAMERA_PINS",
    "GOPIGO3_SPI_PINS",
    "MAX_PCLK_HZ",
    "TURRET_CAMERA_PINS",
    "camera_resources",
    "gopigo3_spi_resources",
    "turret_camera_resources",
]

#: Camera signal -> ECP5 site (BG381 package). ``data`` lists bit 0 first.
CAMERA_PINS = {
    "data": ("B11", "C11", "A10", "A11", "A9", "B10", "B9", "C10"),
    "xclk": "A7",
    "pclk": "A8",
    "href": "C8",
    "vsync": "B8",
    "siod": "H4",
    "sioc": "G5",
    "reset_n": "C18",
}

#: The pan camera's signal -> ECP5 site (gpio 22+..25- data, 26+/- xclk/pclk, 27+/- href/vsync,
#: 19+/- siod/sioc); no reset pin of its own.
TURRET_CAMERA_PINS = {
    "data": ("B15", "C15", "B17", "C17", "C16", "D16", "D14", "E14"),
    "xclk": "B13",
    "pclk": "C13",
    "href": "D13",
    "vsync": "E13",
    "siod": "F17",
    "sioc": "G18",
}

#: GoPiGo3 SPI signal -> ECP5 site.
GOPIGO3_SPI_PINS = {
    "ss_n": "C6",
    "sclk": "C7",
    "miso": "D18",
    "mosi": "E17",
}

#: The fastest camera byte clock the timing constraint covers: PCLK never exceeds XCLK
#: (12.5 MHz) with the camera's internal PLL off, as our register table leaves it.
MAX_PCLK_HZ = 12.5e6

_IO = Attrs(IO_TYPE="LVCMOS33")


def _camera(number, p):
    return Resource(
        "ov7670",
        number,
        Subsignal("data", Pins(" ".join(p["data"]), dir="i")),
        Subsignal("xclk", Pins(p["xclk"], dir="o"), Attrs(DRIVE="8")),
        Subsignal("pclk", Pins(p["pclk"], dir="i"), Clock(MAX_PCLK_HZ)),
        Subsignal("href", Pins(p["href"], dir="i")),
        Subsignal("vsync", Pins(p["vsync"], dir="i")),
        Subsignal("siod", Pins(p["siod"], dir="io"), Attrs(PULLMODE="UP")),
        Subsignal("sioc", Pins(p["sioc"], dir="o"), Attrs(PULLMODE="UP")),
        *([Subsignal("reset", PinsN(p["reset_n"], dir="o"))] if "reset_n" in p else []),
        _IO,
    )


def camera_resources():
    """The OV7670 as one Amaranth ``Resource`` named ``ov7670``."""
    return [_camera(0, CAMERA_PINS)]


def turret_camera_resources():
    """The pan camera: ``ov7670`` number 1."""
    return [_camera(1, TURRET_CAMERA_PINS)]


def gopigo3_spi_resources():
    """The GoPiGo3's SPI bus as one Amaranth ``Resource`` named ``gopigo3_spi``."""
    p = GOPIGO3_SPI_PINS
    return [
        Resource(
            "gopigo3_spi",
            0,
            Subsignal("cs", PinsN(p["ss_n"], dir="o")),
            Subsignal("clk", Pins(p["sclk"], dir="o")),
            Subsignal("cipo", Pins(p["miso"], dir="i"), Attrs(PULLMODE="UP")),
            Subsignal("copi", Pins(p["mosi"], dir="o")),
            _IO,
        )
    ]
