"""Numbers stated in the text of Chen, Li, Liu & Makse, Soft Matter 2016 (arXiv:1509.07012), shown beside ours in the figures,
and the list of its claims with what this package checks of each.

Only numbers printed in the text or its tables are here; values that exist only as points in
the paper's plots (Figs. 3-5, 7-10) are not available and are not invented.
"""
from __future__ import annotations

# Table 2, "Packing structures when charged after formation" (r_p = 2 um, U_0 = 1 m/s,
# gamma = 10 mJ/m^2; N = 2000, L = 28 r_p): charge q [e_0], phi, <Z>
TABLE2 = ((0.0, 0.3249, 3.2056), (260.0, 0.3248, 3.2056), (400.0, 0.3247, 3.2056))
TABLE2_CASE = (2.0, 1.0)          # its (r_p [um], U_0 [m/s]), also the case of Fig. 2
# Sec. 3: "The volume fraction for packings of neutral particles phi_0 ranges from 0.270 to 0.363"
PHI0_RANGE = (0.270, 0.363)
# Sec. 3: "a line with a slope of two nicely describe ... phi_0/phi - 1" (log-log vs q)
EXPANSION_SLOPE = 2.0
# Sec. 3: "the relative decrease of phi can reach a maximum of 40%"
MAX_RELATIVE_DECREASE = 0.40
# Sec. 4.2: the adhesive loose packing (ALP) limit "<Z> = 2 and phi = 1/2^3"
ALP_Z, ALP_PHI = 2.0, 1.0 / 8.0
# Sec. 4.1: F_C / F_E ~ 1e4 for the Table 2 charges; Fig. 7: |F_n / F_C| < 0.1
FC_OVER_FE = 1.0e4
FORCE_RANGE = 0.1
# Sec. 4.2: K_eff = 20 N_tot (L/r_p)^-2 = 51 for all the paper's cases; all have Ad* > 1
K_EFF = 51.0

# Colours of the coordination number Z in the rendered packings (the paper's Fig. 2 colours
# by Z without a legend): one colour per Z = 0 .. 7, the last for Z >= 8. Used by LAMMPS's
# dump image (dump_modify color/amap) and by the matplotlib colour bar, so both agree.
Z_COLORS = (
    (0.55, 0.55, 0.55),   # 0  grey
    (0.45, 0.20, 0.65),   # 1  purple
    (0.15, 0.35, 0.85),   # 2  blue
    (0.10, 0.70, 0.80),   # 3  cyan
    (0.20, 0.70, 0.25),   # 4  green
    (0.95, 0.85, 0.15),   # 5  yellow
    (0.98, 0.55, 0.10),   # 6  orange
    (0.85, 0.15, 0.15),   # 7  red
    (0.45, 0.05, 0.10),   # >= 8 dark red
)

# The paper's claims and what this package checks of each (`granular-charged reproduce`).
CLAIMS = (
    ("Table 2: charging a formed neutral packing (q = 0 -> 260, 400 e0) leaves phi and <Z> "
     "unchanged", "checked: charged-after-formation runs (table2.csv, table2.png)"),
    ("Fig. 3: phi decreases with q (phi_0 = 0.270-0.363 for the neutral packings)",
     "checked at reduced size: phi vs q (phi_vs_q.png)"),
    ("Fig. 3: phi_0/phi - 1 grows as q^2 (slope 2 in log-log), up to 40 %",
     "checked at reduced size: `granular-charged reproduce` fits the slope over 6 charges with "
     "a bootstrap uncertainty over the seeds (expansion_fit.json)"),
    ("Fig. 2: looser, chain-like packings with lower Z when charged",
     "shown: rendered packings coloured by Z (packing_*.png), f(Z) (fZ.png)"),
    ("Fig. 6/7: force network and narrow, nearly symmetric force pdf |F_n/F_C| < 0.1, shifted "
     "to tension after charging", "shown: force_network.png, force_pdf.png"),
    ("Fig. 4: the sqrt(3) peak of g(r) vanishes when charged", "shown: rdf.png (not asserted)"),
    ("Fig. 8: the Coulomb field decelerates an incident particle before contact",
     "shown: tracer_energy.png"),
    ("Fig. 9: phi and <Z> collapse on Ad* = gamma / (rho U0^2 (1 - E*) r_p) for Ad* > 1",
     "checked at reduced size by `granular-charged reproduce` (collapse.csv, phi_Z_vs_Adstar.png)"),
    ("Fig. 10: states on the Edwards-ensemble phase diagram phi(Z) towards ALP (Z = 2, phi = 1/8)",
     "NOT covered: the g_2(r, Z) model of Liu et al. 2015 (Eqs. 9-10) is not implemented; the "
     "ALP point is drawn beside our points only"),
    ("The paper's sizes (N = 2000, L = 28 r_p) and 3 r_p slices of full packings",
     "NOT covered by the demo (N = 500, L = 14 r_p); `reproduce --size paper` runs them "
     "(doc/reproduction.md, paper-size column)"),
)
