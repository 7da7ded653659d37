"""Running many independent jobs and saving what they make.

An experiment splits its work into jobs (:mod:`.job`: a function and its JSON arguments,
saved as a file when it finishes); a backend (:mod:`.backends`: a local process pool or
Ray) runs them in worker processes (:mod:`.workers`: how many, single-threaded); a run
(:mod:`.run`) saves each result as it finishes, resumes an interrupted run and writes
``results.json`` and ``run.json``. :mod:`.output` writes JSON and figures atomically and
checks output folders before work starts. Training sweeps and the experiments both run
on it.
"""
