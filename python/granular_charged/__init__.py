"""GRANULAR-CHARGED Python package: run the deposition decks through LAMMPS's Python module,
sweep parameters, analyse packings and draw the figures of Chen, Li, Liu & Makse (Soft Matter
2016).

Command line: ``granular-charged`` (or ``python3 -m granular_charged``), see doc/python.md.
Subpackages, each importing only those listed after it, and ``studies`` and ``figures``
not each other (doc/python.md, "Package layout"):

- ``cli``: the command line's subcommands, which draw the studies' figures (only ``__main__``
  imports it);
- ``studies``: many runs (sweeps, study files, demo, reproduce) and the Snakemake engine;
- ``figures``: the paper's figures and the studies' figures;
- ``run``: one run (the LAMMPS build, the decks and their variables, populations, the child
  process, logs, estimates);
- ``analysis``: packings, tables and measures from dumps and logs;
- ``params`` (Ad, E*, Ad*, JKR scales, time step) and ``paper`` (the paper's numbers).

The input decks are package data (``granular_charged/decks``).
"""
__version__ = "0.2.0"
