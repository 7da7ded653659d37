"""The paper's experiments and the benchmarks, as library code called by ``vc-gym``."""
