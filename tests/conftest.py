"""Test-wide settings: property tests draw the same examples on every run (a seed fixes every
random choice), so a CI result never depends on luck; set HYPOTHESIS_PROFILE=explore to draw
fresh examples locally."""

import os

from hypothesis import settings

settings.register_profile("deterministic", derandomize=True, database=None)
settings.register_profile("explore")
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "deterministic"))
