"""`inject sequential` of in.deposition: one particle at a time, started near the bed with the
speed of a fall from H (doc/deposition.md, "Sequential injection").

Size: N = 25 in L = 6 r_p, H = 60 r_p; ~10 s per run on a loaded 2-core machine. Nothing here is
statistical: the assertions are the protocol's own bookkeeping and a closed form.
"""
import json
import re
from pathlib import Path

SMALL = ["--N", 25, "--seed", 1, "--var", "L_rp", 6, "--var", "H_rp", 60, "--var", "inject",
         "sequential", "--no-render"]


def _run(cli, tmp_path, q, *extra, size=SMALL):
    cli(["-q", "run", "--out", tmp_path, "--q", q, *size, *extra], cwd=tmp_path)
    (wd,) = [d for d in Path(tmp_path).iterdir() if d.is_dir()]
    res = json.loads((wd / "result.json").read_text())
    # the one-by-one loop's runs are in log.inject.lammps, the rest (and the warnings) in
    # log.lammps: read in the order they were written
    inner = wd / "log.inject.lammps"
    log = (inner.read_text() if inner.exists() else "") + (wd / "log.lammps").read_text()
    return res, log


def test_sequential_charged_start_field_is_the_sheet_field(cli, tmp_path):
    """Every particle is deposited, and the Coulomb force measured on the last one at its start
    height h = z_top + L/2 is the sheet field 2 pi k_e q Q_bed / L^2 of the bed below it: the
    assumption behind the fast-forward v^2 = U_0^2 + 2 (H - h) (g - F_C / m). The lateral
    Fourier modes of the bed's field decay as exp(-2 pi d / L) (d the height above the
    charges), exp(-pi) = 0.04 for the top particles at d = L/2 and less for the rest; between
    h and H they decay further. Asserted: |F_C / F_sheet - 1| < 0.01 for the last particle,
    so the work done between H and h is the sheet field's to 1 %. Measured: -0.008."""
    res, log = _run(cli, tmp_path, 400)
    assert res["inserted"] == 25 and res["natoms"] == 25 and res["lost"] == 0
    m = re.search(r"^GC SEQ done: FC/Fsheet-1 max (\S+) last (\S+), (\d+) particles had not settled",
                  log, re.M)
    assert m, "no GC SEQ summary in log.lammps"
    assert abs(float(m.group(2))) < 0.01
    assert int(m.group(3)) == 0


def test_sequential_stops_at_the_levitation_limit(cli, tmp_path):
    """With q = 3000 e0 the bed's sheet field soon outweighs the particle's kinetic energy over
    the fall from H: the deposition ends with a warning instead of creating a particle that
    cannot land, and result.json says how many were deposited."""
    res, log = _run(cli, tmp_path, 3000)
    assert "cannot reach" in log
    assert 1 <= res["inserted"] < 25 and res["natoms"] == res["inserted"]
    assert f"only {res['inserted']} of 25 particles were deposited" in res["warning"]


def test_sequential_plane_rain_keeps_its_interval(cli, tmp_path):
    """seq_gap_rp > 0: a particle every seq_gap_rp r_p / U_0 from the start plane, without
    waiting for the landing. All 25 are deposited, and the injection phase is exactly 25 runs
    of ceil(2 r_p / U_0 / dt) = 656 steps (dt = 6.1046 ns for r_p = 2 um, U_0 = 1 m/s)."""
    res, log = _run(cli, tmp_path, 400, "--var", "seq_gap_rp", 2)
    assert res["inserted"] == 25 and res["natoms"] == 25 and res["lost"] == 0
    runs = re.findall(r"^Loop time of \S+ on \d+ procs for (\d+) steps", log, re.M)
    assert runs.count("656") == 25


def test_plane_rain_start_plane_follows_the_resting_bed(cli, tmp_path):
    """In a plane rain two particles can meet in flight (or a pair rebound from the bare floor)
    and drift upwards while touching. The start plane h = z_top + seq_dz_L L must follow the
    resting bed, not such a pair: when it followed them, the plane and the lid rose with the
    pair at N = 2000, L = 28 r_p until h left the box (at this size: h up to 25 r_p and three
    particles still flying at the end). Asserted: all 40 inserted, and no start plane was more
    than seq_dz_L L = 7 r_p (+ 0.5 r_p for the bed's growth between the last two starts) above
    the final bed top. Measured: 11.5 r_p against 4.7 + 7.5. Not asserted: that nothing flies
    at the end. On this sparse bed a particle that rebounds flies a ballistic arc of a few ms
    (nothing damps it), and whether one is still in the air when the settling ends is the
    seed's: seeds 1-30 of this command left one in 9 runs with coul_near 2 and in 6 with
    coul_near 3."""
    rp = 2.0e-6
    res, log = _run(cli, tmp_path, 400, size=[
        "--N", 40, "--seed", 1, "--var", "L_rp", 28, "--var", "inject", "sequential",
        "--var", "seq_dz_L", 0.25, "--var", "seq_gap_rp", 4, "--no-render",
        # the loop's commands echoed (in log.inject.lammps): the start heights are read there
        "--var", "split_log", "yes", "--var", "log_file", "log.lammps"])
    assert res["inserted"] == 40
    starts = [float(h) for h in re.findall(r"^\s*variable\s+h equal ([0-9.eE+-]+)\s*$", log, re.M)]
    assert len(starts) == 40
    # the last thermo block of the sequential section: its columns name c_ztop
    blocks = re.findall(r"^\s*Step .*c_ztop.*\n((?:\s*[0-9].*\n)+)", log, re.M)
    header = re.findall(r"^\s*(Step .*c_ztop.*)$", log, re.M)[-1].split()
    ztop = float(blocks[-1].strip().splitlines()[-1].split()[header.index("c_ztop")])
    assert max(starts) <= ztop + 7.5 * rp, (max(starts) / rp, ztop / rp)


def test_plane_without_a_free_place_ends_with_a_warning(cli, tmp_path):
    """A start plane too crowded for the next particle (earlier ones still in it: in a 3 r_p
    box no two particles fit side by side within 2 r_p, and with an interval of 0.3 r_p of
    fall the last one is still there) ends the deposition with a warning and a result, as at
    the levitation limit, instead of failing (seen at paper size: 120 e_0, 1 um, after 1816
    particles, where the particles hovered at the plane)."""
    res, log = _run(cli, tmp_path, 0, size=["--N", 6, "--seed", 1, "--var", "L_rp", 3, "--var", "H_rp", 30,
                                            "--var", "inject", "plane", "--var", "seq_gap_rp", 0.3,
                                            "--no-render"])
    assert "finds no free place in the start plane" in log
    assert 1 <= res["inserted"] < 6 and res["natoms"] == res["inserted"]
    assert f"only {res['inserted']} of 6 particles were deposited" in res["warning"]


def test_epd_variables_give_fix_coul_fmm_its_keywords(cli, tmp_path):
    """E0, eps_p and electrode (doc/epd.md) reach fix coul/fmm as efield 0 0 -E0, polarize eps_p
    and electrode 0.0, with the multiple time stepping (doc/polarization.md, section 8) but no
    check; the deposition runs to the end, with fewer evaluations than steps."""
    res, log = _run(cli, tmp_path, 400, "--var", "E0", "1e5", "--var", "eps_p", 3.8, "--var", "electrode", "yes",
                    size=["--N", 4, "--seed", 1, "--var", "L_rp", 6, "--var", "H_rp", 20, "--no-render"])
    assert re.search(r"^fix coul all coul/fmm accuracy 1e-4 farfield exact images 1 every 1024 near \S+ "
                     r"extrapolate yes tolerance 2e-4 efield 0 0 -100000 polarize 3.8 electrode 0.0\s*$",
                     log, re.M)
    assert res["inserted"] == 4 and res["natoms"] == 4 and res["lost"] == 0
    evaluations = float(re.search(r"^GC COUL evaluations (\S+)", log, re.M).group(1))
    steps = float(re.search(r"^GC RESULT steps (\S+)", log, re.M).group(1))
    assert 4 <= evaluations < steps / 2
