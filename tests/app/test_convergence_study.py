"""demos/convergence_study.py: the JSON contract on 2 coarse cut runs (h = a/6, a/12, ~10 s),
bad input, and the helper shared with benchmarks/work_precision.py."""

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "demos" / "convergence_study.py"


def load(name, path):
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules.setdefault(name, mod)
    spec.loader.exec_module(mod)
    return mod


def run(*args):
    return subprocess.run(
        [sys.executable, str(DEMO), *args], capture_output=True, text=True, cwd=ROOT
    )


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("convergence") / "cut"
    r = run("--discretization", "cut", "--sizes", "12,6", "--out", str(out))  # both enforcements
    assert r.returncode == 0, r.stderr
    return out, json.loads((out / "convergence.json").read_text())


def test_contract(study):
    out, d = study
    assert d["discretizations"] == ["cut"] and d["sizes"] == [6, 12]  # sorted coarse to fine
    assert d["enforcements"] == ["penalty", "augmented"] and d["bulk"] == "resolved"
    assert d["groups"] == ["cut-penalty", "cut-augmented"]
    assert d["variants"] == {"cut-penalty": "q1-cut", "cut-augmented": "q1-cut-aug"}
    assert d["hertz_args"]["cut-penalty"] == ["--discretization", "cut", "--enforcement", "penalty"]
    assert d["hertz_args"]["cut-augmented"][-1] == "augmented"
    assert abs(d["a_hertz"] - 0.99822) < 1e-4 and d["case"]["R"] == 10.0
    assert [(r["group"], r["h_divisor"]) for r in d["runs"]] == [
        ("cut-penalty", 6),
        ("cut-penalty", 12),
        ("cut-augmented", 6),
        ("cut-augmented", 12),
    ]
    for r in d["runs"]:
        assert r["ok"] and r["discretization"] == "cut"
        assert r["variant"] == d["variants"][r["group"]]
        assert abs(r["h"] - d["a_hertz"] / r["h_divisor"]) < 1e-12
        prm = r["hertz_parameters"]
        assert prm["discretization"] == "cut"
        # the resolved bulk: an 80 a x 40 a block
        assert abs(prm["width"] - 80 * d["a_hertz"]) < 1e-9
        assert abs(prm["depth"] - 40 * d["a_hertz"]) < 1e-9
        assert r["num_dofs"] > 0 and r["timing_s"]["total"] > 0
        assert set(r["errors"]) == {
            "half_width_rel_error",
            "peak_pressure_rel_error",
            "pressure_rel_l2_error",
            "pressure_rel_l2_error_circle",
        }
        for f in ("metrics.json", "tractions.csv"):
            assert (out / r["files"] / f).is_file()
    assert (out / "convergence.png").stat().st_size > 0
    for g in d["groups"]:
        s = d["summary"][g]
        assert s["runs_ok"] == 2 and s["runs_failed"] == 0
        assert set(s) >= {"rates_vs_h", "local_rates_vs_h", "errors_decrease_monotonically"}
        assert len(s["local_rates_vs_h"]["pressure_rel_l2_error"]) == 1


def test_errors_decrease(study):
    _, d = study
    for g in d["groups"]:
        s = d["summary"][g]
        coarse, fine = (r["errors"] for r in d["runs"] if r["group"] == g)
        # p(x) L2 error, a/6 -> a/12: penalty 5.26 -> 3.06 % (rate 0.78), augmented 3.15 ->
        # 1.61 % (0.96)
        assert fine["pressure_rel_l2_error"] < coarse["pressure_rel_l2_error"]
        assert fine["peak_pressure_rel_error"] < coarse["peak_pressure_rel_error"]
        assert s["errors_decrease_monotonically"]["pressure_rel_l2_error"] is True
        assert 0.5 < s["rates_vs_h"]["pressure_rel_l2_error"] < 2.0
        assert s["check"]["passed"] is True
        # against the circle as well (reported, not checked): it decreases too, and differs
        # from the error against Hertz by less than the two references differ (0.40 % here)
        assert fine["pressure_rel_l2_error_circle"] < coarse["pressure_rel_l2_error_circle"]
        assert s["rates_vs_h"]["pressure_rel_l2_error_circle"] > 0.5
        for e in (coarse, fine):
            assert abs(e["pressure_rel_l2_error_circle"] - e["pressure_rel_l2_error"]) <= 0.0045
    # the augmented Lagrangian below the penalty at both sizes
    pen, aug = ([r for r in d["runs"] if r["group"] == g] for g in d["groups"])
    for p, a in zip(pen, aug):
        assert a["errors"]["pressure_rel_l2_error"] < p["errors"]["pressure_rel_l2_error"]


@pytest.mark.parametrize(
    "args,name",
    [
        (["--sizes", "10"], "--sizes"),
        (["--sizes", "10,10"], "--sizes"),
        (["--sizes", "1,10"], "--sizes"),
        (["--sizes", "10,x"], "--sizes"),
        (["--discretization", "p1"], "--discretization"),
        (["--enforcement", "nitsche"], "--enforcement"),
        (["--bulk", "fine"], "--bulk"),
        (["--R", "0"], "--R"),
        (["--R", "nan"], "--R"),
        (["--timeout", "-1"], "--timeout"),
    ],
)
def test_bad_input(tmp_path, args, name):
    out = tmp_path / "never"
    r = run(*args, "--out", str(out))
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and name in lines[0], r.stderr
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_out_is_a_file(tmp_path):
    f = tmp_path / "file"
    f.write_text("x")
    r = run("--out", str(f))
    assert r.returncode == 2 and "--out" in r.stderr and f.read_text() == "x"


def test_work_precision_shares_the_runner():
    cs = load("convergence_study", DEMO)
    wp = load("work_precision", ROOT / "benchmarks" / "work_precision.py")
    # one runner: the benchmark calls the demo module's run_hertz (no second copy)
    assert Path(wp.demo.__file__).resolve() == Path(cs.__file__).resolve()
    assert wp.demo.run_hertz.__code__.co_firstlineno == cs.run_hertz.__code__.co_firstlineno
    assert wp.VARIANTS["q1-cut"] == ["--discretization", "cut", "--enforcement", "penalty"]
    assert wp.parse([]).variants == [
        "p1-tri",
        "p1-quad",
        "q1-cut",
        "p1-tri-al",
        "q1-cut-al",
        "q1-cut-al-z1",
        "p1-tri-layers",
    ]
    # the augmented variants with the projection they were measured with (the closest p(x))
    al = wp.VARIANTS["q1-cut-al"]
    assert al[:4] == ["--discretization", "cut", "--enforcement", "augmented"]
    assert al[4:] == ["--multiplier-mass", "lumped", "--zone", "1.2"]
    assert wp.parse(["--quick"]).variants == ["p1-tri", "q1-cut"]
    # --R: the case's radius (Hertz at R = 40: a = 1.99643), refused outside (0, inf)
    assert wp.parse(["--R", "40"]).R == 40.0 and wp.parse([]).R == 10.0
    assert wp.hertz_half_width(40.0) == pytest.approx(1.9964341, rel=1e-6)
    with pytest.raises(SystemExit):
        wp.parse(["--R", "-1"])
    assert wp.loglog_rate([1, 2, 4], [1, 4, 16]) == pytest.approx(2.0)
    assert wp.loglog_rate([1, 1], [1, 2]) is None


def test_work_precision_reference_measure(tmp_path):
    """The error against the fine reference: exact on profiles whose interpolants it integrates
    (0 for the same curve sampled at other points, 1 for a zero profile), the known value for
    a scaled one, and a demo's tractions.csv read back sorted."""
    import numpy as np

    wp = load("work_precision", ROOT / "benchmarks" / "work_precision.py")
    a = 1.0
    xr = np.linspace(-1.2, 1.2, 2401)
    ref = (xr, np.clip(1 - xr**2, 0, None))  # a parabola's hat: piecewise-linear to 1e-7
    xs = np.linspace(-1.0, 1.0, 801)[::-1]  # other points, unsorted on purpose
    same = np.sort(xs), 1 - np.sort(xs) ** 2
    assert wp.profile_error(same, ref, a) == pytest.approx(0.0, abs=1e-5)
    assert wp.profile_error((same[0], 1.1 * same[1]), ref, a) == pytest.approx(0.1, rel=1e-4)
    assert wp.profile_error((xs[:2] * 0, np.zeros(2)), ref, a) == pytest.approx(1.0)
    f = tmp_path / "tractions.csv"
    f.write_text("x,y,p_n,p_t,gap_n,slip,state\n0.5,0,2,0,0,0,slip\n-0.5,0,1,0,0,0,slip\n")
    x, p = wp.read_profile(f)
    assert list(x) == [-0.5, 0.5] and list(p) == [1.0, 2.0]
    assert wp.parse(["--reference-divisor", "0"]).reference_divisor == 0
    assert wp.parse(["--quick"]).reference_divisor == wp.QUICK_REFERENCE_DIVISOR
    with pytest.raises(SystemExit):
        wp.parse(["--reference-divisor", "-3"])
