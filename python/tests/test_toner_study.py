"""The example study of a toner-like binary, bipolar powder (examples/toner/toner.toml), reduced
to N = 40 particles in a box 6 r_p wide, 2 seeds and 2 grid points (both species uncharged; both at their full
charge densities, varied together), end to end through `granular-charged study` and the
workflow engine: its tables carry the study's name and per-species rows for both species
(named as in the study file), and its figures include the force distribution."""
import csv
import re

from lammps_runs import SRC

TONER = SRC / "examples" / "toner" / "toner.toml"


def _reduced(text: str) -> str:
    text = re.sub(r"(?m)^N = \d+", "N = 40", text)
    # a narrower box, so that 40 particles make a bed thick enough for the analysis slab
    text = re.sub(r"(?m)^L_rp = \d+", "L_rp = 6", text)
    text = re.sub(r"(?m)^seeds = .*$", "seeds = [1, 2]", text)
    text = re.sub(r"(?m)^together = .*$",
                  "together = {q_sigma = [0, -5e-7], q_sigma_2 = [0, 5e-7]}", text)
    assert "N = 40" in text and "L_rp = 6" in text and "seeds = [1, 2]" in text and "q_sigma = [0, -5e-7]" in text
    return text


def _rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def test_toner_study_end_to_end(cli, tmp_path):
    study = tmp_path / "toner.toml"
    study.write_text(_reduced(TONER.read_text()))
    # a hang guard (the cli fixture's default is 600 s): ~2 min idle, 4 runs one at a time
    r = cli(["study", study, "--jobs", "1", "--no-render"], tmp_path, timeout=1200)
    out = tmp_path / "toner-output"
    runs = _rows(out / "runs.csv")
    assert len(runs) == 4, r.stderr
    assert {row["study"] for row in runs} == {"toner-like binary powder"}
    assert {(float(row["q_sigma"]), float(row["q_sigma_2"])) for row in runs} == \
        {(0.0, 0.0), (-5e-7, 5e-7)}
    species = _rows(out / "species_summary.csv")
    names = {(float(row["q_sigma"]), row["species_name"]) for row in species}
    assert names == {(q, n) for q in (0.0, -5e-7) for n in ("polymer", "silica")}, species
    for row in species:
        assert 0.0 < float(row["phi"]) < 0.6 and float(row["Z"]) > 0.0, row
    assert (out / "figures" / "force_pdf.png").exists()
