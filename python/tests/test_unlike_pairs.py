"""Unlike spheres (two atom types, two radii, two materials, the unlike pair mixed by the
sub-models) against the closed forms with the mixing rules of doc/populations.md:
R = r1 r2 / (r1 + r2), 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2, gamma = sqrt(gamma1 gamma2),
e = sqrt(e1 e2). Both pair styles the deck uses (granular, granular/opt)."""
import math

import pytest

from granular_charged.params import jkr_force_of_overlap, jkr_scales

R1, R2 = 2.0e-6, 3.5e-6
MAT1 = dict(E=2.0e8, e=0.5, nu=0.33, gamma=0.010, rho=2500.0)
MAT2 = dict(E=1.0e9, e=0.8, nu=0.25, gamma=0.040, rho=4000.0)


def mixed(m1, m2):
    Es = 1.0 / ((1 - m1["nu"] ** 2) / m1["E"] + (1 - m2["nu"] ** 2) / m2["E"])
    return {"Estar": Es, "gamma": math.sqrt(m1["gamma"] * m2["gamma"]),
            "e": math.sqrt(m1["e"] * m2["e"]), "R": R1 * R2 / (R1 + R2)}


def two_types(style, m1=MAT1, m2=MAT2):
    from lammps import lammps
    lmp = lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
    contact = ("jkr/marshall {E} {e} {nu} {gamma} damping marshall tangential marshall 0.3 "
               "rolling marshall 0.01 twisting marshall/jkr")
    for c in ["units si", "atom_style sphere", "atom_modify map array", "boundary f f f",
              "newton off", "comm_modify vel yes",
              "region box block -2e-5 2e-5 -2e-5 2e-5 -2e-5 2e-5 units box", "create_box 2 box",
              "create_atoms 1 single 0 0 0 units box",
              f"create_atoms 2 single {R1 + R2 + 1e-6} 0 0 units box",
              f"set atom 1 diameter {2 * R1} density {m1['rho']}",
              f"set atom 2 diameter {2 * R2} density {m2['rho']}",
              f"pair_style {style}", "pair_coeff 1 1 " + contact.format(**m1),
              "pair_coeff 2 2 " + contact.format(**m2),   # 1 2: mixed by the sub-models
              "neighbor 1e-6 bin", "neigh_modify delay 0 every 1 check yes",
              "fix nve all nve/sphere", "timestep 2e-11", "thermo 0",
              "variable dx equal x[2]-x[1]", "variable dv equal vx[2]-vx[1]",
              "variable f2 equal fx[2]"]:
        lmp.command(c)
    return lmp


@pytest.mark.parametrize("style", ["granular", "granular/opt"])
def test_unlike_force_law_pull_off_and_critical_overlap(style):
    mx = mixed(MAT1, MAT2)
    sc = jkr_scales(mx["R"], mx["Estar"], mx["gamma"])
    lmp = two_types(style)

    def fx_at(delta):
        lmp.command(f"set atom 2 x {R1 + R2 - delta:.17g}")
        lmp.command("run 0 post no")
        return lmp.extract_variable("f2")

    try:
        # attached branch: 1e-6 of F_C covers the solver of the JKR root and position rounding
        for dd in (1.0, 0.3, 0.0, -0.5, -0.9):
            f = fx_at(dd * sc["deltaC"])
            ref = jkr_force_of_overlap(dd * sc["deltaC"], mx["R"], mx["Estar"], mx["gamma"])[0]
            assert f / sc["FC"] == pytest.approx(ref / sc["FC"], abs=1e-6), dd
        # the pull-off force is -F_C = -3 pi gamma R (the minimum over the attached branch):
        # 2e-3 steps in delta resolve the flat minimum to 1e-5
        fmin = min(fx_at(-k * 2e-3 * sc["deltaC"]) for k in range(0, 495))
        assert fmin / sc["FC"] == pytest.approx(-1.0, abs=1e-5)
        # contact breaks at the critical overlap -delta_C of R and the mixed gamma
        assert fx_at(-0.999 * sc["deltaC"]) < 0.0
        assert fx_at(-1.001 * sc["deltaC"]) == 0.0
    finally:
        lmp.close()


@pytest.mark.parametrize("style", ["granular", "granular/opt"])
def test_unlike_restitution_is_the_mixed_e(style):
    """Head-on, no adhesion (gamma = 0 on both): the relative speed after over before is
    e = sqrt(e1 e2) to 0.2 % (the like-sphere tolerance of test_jkr_marshall: time step)."""
    m1, m2 = dict(MAT1, gamma=0.0), dict(MAT2, gamma=0.0)
    lmp = two_types(style, m1, m2)
    try:
        lmp.command(f"set atom 2 x {R1 + R2 + 1e-8:.17g}")
        lmp.command("set atom 1 vx 2.5")
        lmp.command("set atom 2 vx -2.5")
        lmp.command("run 0 post no")
        for _ in range(400):
            lmp.command("run 500 post no")
            if (lmp.extract_variable("dx") > R1 + R2 + 1e-8
                    and lmp.extract_variable("dv") > 0):
                break
        e_app = lmp.extract_variable("dv") / 5.0
        assert e_app == pytest.approx(mixed(m1, m2)["e"], rel=2e-3)
    finally:
        lmp.close()
