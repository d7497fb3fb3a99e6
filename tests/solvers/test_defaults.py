"""The tuned numbers live in dolfinx_forms.defaults.TUNING, each with its study, and every
module reads them when it needs them (a study or a user replaces one value, nothing else)."""

import dataclasses

import pytest
from mpi4py import MPI

from dolfinx_forms import defaults
from dolfinx_forms.solvers.options import options
from dolfinx_forms.solvers.problem import ContactProblem
from meshes.cut import patch_cut_scene
from meshes.patch import patch_dirichlet


def test_every_tuned_number_names_its_study():
    names = {f.name for f in dataclasses.fields(defaults.Tuning)}
    assert set(defaults.STUDIES) == names
    for name, study in defaults.STUDIES.items():
        assert study.startswith("benchmarks/"), name


def test_tuning_is_read_when_a_problem_is_made(monkeypatch):
    """The augmented Lagrangian's eps_n = consistent_eps0 h / E_c (eq 51): doubling the
    factor in TUNING doubles the problem's eps_n; the multiplier spacing likewise."""
    scene = patch_cut_scene(MPI.COMM_SELF, n=4, interface=0.6)
    laws = {b.tag: (1.0, 0.3) for b in scene.bodies}

    def problem():
        return ContactProblem(
            scene,
            laws,
            dirichlet=patch_dirichlet(0.01),
            **options(enforcement="augmented", band=0.1),
        )

    before = problem()
    t = defaults.TUNING
    twice = dataclasses.replace(t, consistent_eps0=2 * t.consistent_eps0)
    monkeypatch.setattr(defaults, "TUNING", twice)
    assert problem().eps_n == pytest.approx(2 * before.eps_n, rel=1e-12)


def test_regularisation_scales_the_augmented_eps_n_only():
    """ContactOptions.regularisation multiplies the augmented Lagrangian's point-wise eps_n
    (the MPM's finite-strain bodies take 0.1 of it); the penalty's eps (eps0 h / E_c) and the
    tangential eps_t are the user's / the tuned ones whatever it is."""
    scene = patch_cut_scene(MPI.COMM_SELF, n=4, interface=0.6)
    laws = {b.tag: (1.0, 0.3) for b in scene.bodies}

    def problem(**kw):
        bcs = patch_dirichlet(0.01)
        return ContactProblem(scene, laws, dirichlet=bcs, **options(band=0.1, **kw))

    tuned, stiff = (problem(enforcement="augmented", regularisation=r) for r in (1.0, 0.1))
    assert stiff.eps_n == pytest.approx(0.1 * tuned.eps_n, rel=1e-12)
    assert stiff.contact.eps_t == tuned.contact.eps_t
    penalty = [problem(eps0=0.5, regularisation=r).eps_n for r in (1.0, 0.1)]
    assert penalty[0] == penalty[1]
