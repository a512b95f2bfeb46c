"""Only an input that turns fully (``full_turn``, ``--full-turn``, and a closed SVG shape): the trial's drawn egg came
back as a triple-rocker swung 344 degrees out and back, its curve never traced between two targets."""

import numpy as np
import pytest
from clicheck import fails_cleanly

from planar.errors import InputError
from planar.synth.path import synthesise_path
from planar.synth.targets import svg_closed

EGG = (
    '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 80"><path d="M 10 40 C 10 10 90 10 90 40 '
    'C 90 70 10 70 10 40{z}"/></svg>'
)


@pytest.mark.parametrize(
    ("shape", "closed"),
    [
        (EGG.format(z=" Z"), True),
        (EGG.format(z=""), False),
        ('<svg xmlns="http://www.w3.org/2000/svg"><circle cx="5" cy="5" r="4"/></svg>', True),
        ('<svg xmlns="http://www.w3.org/2000/svg"><polyline points="0,0 10,0 10,10"/></svg>', False),
        ('<svg xmlns="http://www.w3.org/2000/svg"><polygon points="0,0 10,0 10,10"/></svg>', True),
    ],
)
def test_svg_closed_reads_the_shape_the_targets_come_from(tmp_path, shape, closed):
    f = tmp_path / "s.svg"
    f.write_text(shape)
    assert svg_closed(f) is closed


def test_full_turn_is_a_flag_and_refuses_rocking(tmp_path, capsys):
    t = np.array([[0.0, 0.0], [1.0, 0.2], [2.0, 0.1], [2.5, 1.0], [1.0, 1.5]])
    with pytest.raises(InputError, match="full_turn"):
        synthesise_path(t, None, full_turn="yes")
    src = tmp_path / "egg.svg"
    src.write_text(EGG.format(z=" Z"))
    out = tmp_path / "e.toml"
    argv = ["synth", "path", str(src), "-o", str(out), "--full-turn", "--rocking"]
    fails_cleanly(capsys, argv, "--full-turn", "--rocking", out=out)


@pytest.mark.slow
def test_full_turn_keeps_the_rocking_arcs_out():
    """12 targets on random triple-rockers' arcs, the quick atlases, tolerance 1e-6: without ``full_turn`` the search
    returns an input that rocks on some (the closed-curve atlas, its windows included, is not within the tolerance
    there; a double-rocker's arc is often traced by a cognate's crank, which the windows find); with it, never, and
    the result says the rocking arcs were not tried when it is not within the tolerance."""
    from planar.bench.synthesis_rocking import rocking_problem
    from planar.synth.arcs import QUICK_FOURBARS, build_arcs

    arcs = build_arcs(QUICK_FOURBARS)
    rng = np.random.default_rng(7)
    rocked = 0
    for _ in range(2):
        t = rocking_problem(rng, "triple", 12)["targets"]
        d = synthesise_path(t, None, budget="quick", arcs=arcs, ordered=True, tolerance=1e-6)
        rocked += d.checks["input"] == "rocks"
        f = synthesise_path(t, None, budget="quick", arcs=arcs, ordered=True, tolerance=1e-6, full_turn=True)
        assert f.checks["input"] == "turns fully"
        if not f.checks["ok_accuracy"]:
            assert "rocking arcs not tried" in f.checks["found_by"]
    assert rocked >= 1
