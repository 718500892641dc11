"""Helpers shared by Candela's benchmark scripts (bench/cornell.py now, the relMSE-at-equal-
time harness bench/compare_mitsuba later).

Modules:
  machine        -- what the numbers were measured on (CPU, cores, load, date, git revision)
  candela        -- run the `candela` CLI and parse its summary line
  mitsuba_render -- render a Mitsuba 3 scene in a fresh process (also a CLI: one variant,
                    one thread count, JIT warm-up timed apart)
  images         -- EXR I/O through numpy, relMSE, mean-radiance z-tests, orientation check
  report         -- markdown tables
"""
