#!/usr/bin/python3
"""Translation invariance and energy conservation of `fix coul/fmm` with each far field
(doc/fix_coul_fmm.rst, "Far field": `average` and `none` depend on where the cell's faces are).

1. Jump at a face: 300 charges (neutral +-1, or net-charged 1.1 / -0.9) at random in a 20 x 20 x 40 Angstrom box,
   boundary p p f, units real. The atom closest to the x = 0 face is moved by 0.02 A across it
   (x = 0.01 -> -0.01, wrapped to 19.99); the change of the Coulomb energy and the relative RMS
   change of all forces are printed. The physical change of a 0.02 A move is what `exact` gives.
2. NVE drift: the same charges kept apart by a Lennard-Jones repulsion (lj/cut, no Coulomb
   part) at 300 K between reflecting walls at the z faces (elastic: they conserve energy),
   500 fs with the Coulomb energy in pe (fix_modify energy yes): the drift of the total
   energy etotal(500 fs) - etotal(0), kcal/mol, at three time steps (500 to 2000 steps).

Usage: . build/env.sh && /usr/bin/python3 bench/coulomb/farfield_invariance.py
"""
import numpy as np
from lammps import lammps

SETUP = """
units real
atom_style charge
atom_modify map array sort 0 0
boundary p p f
region box block 0 20 0 20 0 40
create_box 1 box
create_atoms 1 random 300 4711 NULL overlap 2.5 maxtry 500
mass 1 39.95
"""
# neutral: +-1 alternating (then average = none: the smeared net charge is zero); charged:
# 1.1 and -0.9 alternating (net charge +30, as a bed of charged particles has)
CHARGES = {"neutral": "2*(id%2)-1", "charged": "2*(id%2)-0.9"}


def instance(charges):
    lmp = lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
    lmp.commands_string(SETUP)
    lmp.commands_string(f"variable qq atom {CHARGES[charges]}\nset group all charge v_qq")
    return lmp


def face_jump(farfield, charges):
    lmp = instance(charges)
    x = lmp.numpy.extract_atom("x")
    i = int(np.argmin(x[:, 0]))
    tag = int(lmp.numpy.extract_atom("id")[i])
    lmp.commands_string(f"""
set atom {tag} x 0.01
pair_style zero 5.0
pair_coeff * *
fix c all coul/fmm accuracy 1e-6 farfield {farfield}
run 0 post no
""")
    e0 = lmp.extract_fix("c", 0, 0)
    f0 = np.array(lmp.gather_atoms("f", 1, 3)).reshape(-1, 3)
    lmp.commands_string(f"set atom {tag} x -0.01\nrun 0 post no")
    e1 = lmp.extract_fix("c", 0, 0)
    f1 = np.array(lmp.gather_atoms("f", 1, 3)).reshape(-1, 3)
    lmp.close()
    return e1 - e0, np.sqrt(((f1 - f0) ** 2).sum() / (f0 ** 2).sum())


def nve_drift(farfield, charges, dt, time=500.0):
    steps = int(round(time / dt))
    lmp = instance(charges)
    lmp.commands_string(f"""
pair_style lj/cut 6.0
pair_coeff * * 0.2 3.0
pair_modify shift yes
neighbor 2.0 bin
velocity all create 300 5 loop geom
fix nve all nve
fix walls all wall/reflect zlo EDGE zhi EDGE
fix c all coul/fmm accuracy 1e-6 farfield {farfield}
fix_modify c energy yes
timestep {dt}
thermo_style custom step etotal pe
run 0 post no
""")
    e0 = lmp.get_thermo("etotal")
    lmp.command(f"run {steps} post no")
    e1 = lmp.get_thermo("etotal")
    lmp.close()
    return e1 - e0, e0


def main():
    print("1. a charge moved 0.02 A across the x = 0 face (kcal/mol; forces relative RMS)")
    for charges in CHARGES:
        for ff in ("exact", "average", "none"):
            de, df = face_jump(ff, charges)
            print(f"   {charges:8s} farfield {ff:8s} dE = {de:+10.4f}   dF = {df:.3e}")
    print("2. NVE, 300 charges, 300 K, 500 fs: etotal(500 fs) - etotal(0), kcal/mol")
    for charges in CHARGES:
        for ff in ("exact", "average", "none"):
            for dt in (1.0, 0.5, 0.25):
                d, e0 = nve_drift(ff, charges, dt)
                print(f"   {charges:8s} farfield {ff:8s} dt = {dt:4.2f} fs: drift {d:+10.3f} "
                      f"(etotal {e0:.2f})")


if __name__ == "__main__":
    main()
