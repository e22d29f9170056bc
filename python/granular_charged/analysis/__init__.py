"""Analyse finished cases: packings from the dumps (packing), the per-run measures of the paper's claims
(measures), tables of runs and per-case summaries (tables), the conventions the paper leaves
open as a table (conventions), the claims quantified over the seeds (claims), and the two-sphere
multipole reference (two_spheres)."""
