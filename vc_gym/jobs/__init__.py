"""Running many independent jobs and saving what they make.

:mod:`.runner` splits work into jobs run by a backend (a local process pool or Ray),
saves each result as it finishes and resumes an interrupted run; :mod:`.output` writes
JSON and figures atomically and checks output folders before work starts. Training
sweeps and the experiments both run on it.
"""
