"""The studies' workflows: the engine that runs a study's cases (Snakemake, engine.py) and its
Snakefile."""
