"""The hardware flow: the design as Verilog (``export.py``), the board top and its bitstream
(``board.py``), the formal proofs (``formal.py``)."""
