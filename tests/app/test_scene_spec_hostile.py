"""Hostile scene descriptions are refused at validation, in-process, with one line naming the
key (issue 29): a name that is a path, expressions that hang or are not finite, a file that is
not UTF-8 text. Values that are fine stay accepted."""

from pathlib import Path

import pytest

from dolfinx_forms.app.scene_spec import SpecError, load, parse_expression

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "demos" / "scenes" / "two_blocks.toml"


@pytest.mark.parametrize(
    "text, why",
    [
        ("9**9**9", "exponent"),  # a hang: 9**(9**9) as integers
        ("x**(2*x)", "exponent"),
        ("1/0", "not a finite number"),
        ("sqrt(-1.0)", "not a finite number"),
        ("exp(1000.0)", "not a finite number"),
        ("log(0*x)", "not a finite number"),
        ("x" * 1001, "at most 1000 characters"),
        ("__import__('os')", "may be called"),
        ("x.real", "unsupported syntax"),
    ],
)
def test_bad_expressions_refused(text, why):
    """Refused by inspection or one float evaluation: `9**9**9` is never computed."""
    with pytest.raises(SpecError, match=why) as e:
        parse_expression(text, "dirichlet[2].value")
    assert str(e.value).startswith("dirichlet[2].value: ")
    assert "\n" not in str(e.value)


@pytest.mark.parametrize("text", ["-0.01 * x", "x**2 + 1/x", "(9**9)**9", "2**-3", "abs(y)"])
def test_good_expressions_accepted(text):
    """Finite at some sample point (1/x is finite away from x = 0, as on a real boundary)."""
    assert parse_expression(text, "v") == text


@pytest.mark.parametrize("name", ["/some/absolute/path", "../../x", "", "..", "a/b", "a b"])
def test_name_is_a_plain_file_name(name):
    with pytest.raises(SpecError, match="^name: a plain file name"):
        load(SCENE, [f'name="{name}"'])


def test_default_name_from_a_file_name_is_made_plain(tmp_path):
    scene = tmp_path / "my scene.toml"
    text = SCENE.read_text()
    scene.write_text(text.replace('name = "two_blocks"\n', ""))
    assert load(scene)["name"] == "my_scene"


def test_binary_file_is_one_line(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_bytes(b'name = "x"\n\xff\xfe\x00 bad\n')
    with pytest.raises(SpecError, match="not a UTF-8 text file") as e:
        load(bad)
    assert "\n" not in str(e.value)


@pytest.mark.parametrize(
    "sets, why",
    [
        (['solver.petsc={ksp_type="bogus"}'], "PETSc refuses ksp_type=bogus"),
        (['solver.petsc={ksp_rtol="1e-10"}'], "does not read ksp_rtol"),
        (['solver.linear_solver="condensed"', 'solver.petsc={ksp_type="cg"}'], "condensed"),
    ],
)
def test_scene_petsc_options_checked_as_the_demos(sets, why):
    """solver.petsc is checked by the demos' check (cli.check_petsc), at validation."""
    with pytest.raises(SpecError, match="^solver.petsc: ") as e:
        load(SCENE, sets)
    assert why in str(e.value)


PATCH = ROOT / "demos" / "scenes" / "patch.toml"


@pytest.mark.parametrize(
    "scene, sets, key, why",
    [
        # h larger than the bodies: the reaction came out 3x small with exit 0
        (PATCH, ["discretization.h=2.0"], "discretization.h", "body 'lower' is 0.5375 across"),
        # the upper block pushed 1 mm into the lower one: reactions 12-28x, exit 0
        (SCENE, ["bodies[1].shape.min=[10.0, 9.0]"], "bodies[1]", "'lower' and 'upper' overlap"),
        # identical bodies
        (SCENE, ['bodies[1].shape={type="box", min=[0.0, 0.0], max=[40.0, 10.0]}'], "bodies[1]",
         "overlap"),
        # a body partly outside the cut grid: clipped silently
        (SCENE, ["bodies[1].shape.max=[30.0, 25.0]"], "bodies[1]", "partly outside the grid"),
        # a self-intersecting polygon (a bow tie)
        (SCENE, ['bodies[1].shape={type="polygon", points=[[10,10],[30,20],[30,10],[10,20]]}'],
         "bodies[1].shape.points", "crosses itself (edges 0 and 2)"),
    ],
)  # fmt: skip
def test_scene_geometry_refused_naming_the_body(scene, sets, key, why):
    with pytest.raises(SpecError) as e:
        load(scene, sets)
    assert str(e.value).startswith(f"{key}: ") and why in str(e.value)


def test_touching_bodies_are_not_an_overlap():
    """The demos' scenes: bodies that touch along a side (two blocks, the patch) or at a
    point (Hertz) pass."""
    for name in ("two_blocks", "patch", "hertz", "mindlin", "disc_squeeze"):
        assert load(ROOT / "demos" / "scenes" / f"{name}.toml")["name"] == name


def test_set_switches_the_discretization_kind():
    """--set discretization.kind="fitted" on a cut scene drops the file's cut-only keys (it
    was refused: "extent: not used by kind = 'fitted'"); the same keys given by --set are
    still checked."""
    spec = load(PATCH, ['discretization.kind="fitted"'])
    assert spec["discretization"]["kind"] == "fitted" and "extent" not in spec["discretization"]
    with pytest.raises(SpecError, match="^discretization.extent: not used by kind = 'fitted'"):
        load(PATCH, ['discretization.kind="fitted"', "discretization.extent=[[0,0],[1,1]]"])
