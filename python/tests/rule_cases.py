"""The cases of the input rules' tests (python/tests/test_rules.py, through Python, and
python/tests_powder/test_rules_deck.py, through lmp): for every rule of
granular_charged/rules.py, deck variables that break it and no other rule, found by a search
over candidate values or given in EXAMPLES."""
import os
import re
import subprocess
from pathlib import Path

from granular_charged import rules
from granular_charged.params import param_names
from lammps_runs import DECK

RULES = [r for r in rules.RULES if r.kind != "derived"]
FIELDS = set(param_names())

# values tried for a rule's variable when the search looks for a case that breaks it
CANDIDATES = ["-1", "0", "0.3", "1", "1.5", "2.5", "4", "7", "100", "1e9", "1e-20", "1e-9",
              "-0.1", "0.9", "1e6", "1e13", "30000", "2.5e-7", "bogus", "2e-6 0", "2e-6 4e-6",
              "1e-6 2e-6 3e-6 4e-6 5e-6 6e-6 7e-6", "1 2 3", "10", "0.5", "2e-6 2"]
# cases the search cannot find (they need more than one variable)
EXAMPLES = {
    "rp_lo#lognormal-range": {"r_dist": "lognormal", "rp_lo": "3e-6", "rp_hi": "5e-6"},
    "rp_hi#lognormal-range": {"r_dist": "lognormal", "rp_lo": "1e-6", "rp_hi": "1.5e-6"},
    "rp_gsd#lognormal-mass": {"r_dist": "lognormal", "rp_gsd": "1.5", "rp_lo": "1.999e-6",
                              "rp_hi": "2.001e-6"},
    "frac#sum": {"species": "2", "frac": "0", "frac_2": "0"},
    "rp_hi#uniform-order": {"r_dist": "uniform", "rp_lo": "3e-6", "rp_hi": "2e-6"},
    "dt_div#flight": {"dt_div": "0.001"},
    "tracer#range": {"tracer": "11", "N": "10"},
    "resume#population": {"resume": "yes", "q_dist": "area"},
}
for s in (2, 3):
    x = f"_{s}"
    EXAMPLES[f"rp_lo{x}#lognormal-range"] = {"species": str(s), f"r_dist{x}": "lognormal",
                                             f"rp_lo{x}": "3e-6", f"rp_hi{x}": "5e-6"}
    EXAMPLES[f"rp_hi{x}#lognormal-range"] = {"species": str(s), f"r_dist{x}": "lognormal",
                                             f"rp_lo{x}": "1e-6", f"rp_hi{x}": "1.5e-6"}
    EXAMPLES[f"rp_gsd{x}#lognormal-mass"] = {"species": str(s), f"r_dist{x}": "lognormal",
                                             f"rp_gsd{x}": "1.5", f"rp_lo{x}": "1.999e-6",
                                             f"rp_hi{x}": "2.001e-6"}
    EXAMPLES[f"rp_hi{x}#uniform-order"] = {"species": str(s), f"r_dist{x}": "uniform",
                                           f"rp_lo{x}": "3e-6", f"rp_hi{x}": "2e-6"}


def rule_id(rule):
    """name#what: the first words of the message, enough to tell a variable's rules apart."""
    same = [r for r in RULES if r.name == rule.name]
    return f"{rule.name}#{same.index(rule)}"


def _context(rule) -> dict:
    """Variables that open the rule's gate, the rest of the population valid."""
    ctx = {}
    gate = rule.when
    m = re.search(r"\$\{species\} >= (\d)", gate)
    if m:
        ctx["species"] = m.group(1)
    for var, word in re.findall(r"x\$\{(\w+)\} == x([\w/]+)", gate):
        ctx[var] = word
    if "${species} != 1 ||" in gate:
        ctx["q_dist"] = "area"
    for var, word in re.findall(r"x\$\{(\w+)\} != x([\w/]+)", gate):
        if var.startswith("r_dist") and word == "discrete" and "||" not in gate:
            ctx[var] = "one"
    for var, word in list(ctx.items()):
        suf = var[len("r_dist"):] if var.startswith("r_dist") else None
        if word in ("uniform", "lognormal"):
            ctx.setdefault(f"rp_lo{suf}", "1e-6")
            ctx.setdefault(f"rp_hi{suf}", "4e-6")
        if word == "discrete":
            ctx.setdefault(f"radii{suf}", "2e-6 4e-6")
    if rule.plausible:
        ctx["exotic"] = "no"
    return ctx


def _problems(vals):
    return rules.problems(vals, first=False)


def _case(rule):
    """Variables that break this rule (its message first among the problems) and that are fine
    without the rule's variable set to the bad value."""
    base = _context(rule)
    for v in CANDIDATES:
        if rule.kind == "word" and v != "bogus":
            continue
        vals = dict(base, **{rule.name: v})
        found = _problems(vals)
        if found and found[0] == _message_of(rule, vals) and not _problems(base):
            return vals
    return None


def _message_of(rule, vals):
    """The message this rule gives for vals, None if it passes (or is gated off)."""
    one = rules.RULES.index(rule)
    saved = rules.RULES[:]
    try:
        rules.RULES[:] = [r for r in saved if r.kind == "derived"] + [saved[one]]
        got = rules.problems(vals)
    finally:
        rules.RULES[:] = saved
    return got[0] if got else None


def _cases():
    out = {}
    by_id = {rule_id(r): r for r in RULES}
    for key, vals in EXAMPLES.items():
        for rid, r in by_id.items():
            if rid not in out and r.name == key.split("#")[0] and _message_of(r, vals) \
                    and _problems(vals)[:1] == [_message_of(r, vals)]:
                out[rid] = vals
    for rid, r in by_id.items():
        if rid not in out:
            found = _case(r)
            if found:
                out[rid] = found
    return out


CASES = _cases()


def _lmp(build_dir, cwd, vals):
    cmd = [str(Path(build_dir) / "lmp"), "-in", str(DECK), "-screen", "none", "-log", "q.log",
           "-nocite"]
    for k, v in vals.items():
        cmd += ["-var", k, v]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    r = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=120)
    log = Path(cwd) / "q.log"
    assert log.exists(), (r.returncode, r.stdout[-2000:], r.stderr[-2000:])
    return r, log.read_text(errors="replace")
