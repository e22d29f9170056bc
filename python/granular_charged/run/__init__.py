"""One case of a study: run_one (one_case.py), the job of the studies' Snakefile."""
