"""Benchmarks (``vc-gym bench NAME``) and the long-run soak test (``vc-gym soak``).

Each prints and saves measured numbers: speed as medians and ratios measured side by
side in one run, accuracy over several seeds.
"""
