"""Every mechanism kind answers Mechanism.part_rates itself; the base refuses by name."""

from __future__ import annotations

import numpy as np
import pytest

from planar.analysis.rates import mechanism_rates
from planar.cams.mechanism import CamMechanism
from planar.core.model import Driver, Mechanism, Part
from planar.core.registry import UnsupportedError
from planar.linkages import FourBar, Linkage
from planar.toys.assembly import ToyAssembly
from planar.windup import elemental
from planar.windup.chain import ToyMechanism
from planar.windup.mechanisms import ELEMENTAL, ElementalMechanism, standalone_motion


class _Still(Mechanism):
    """A kind with no closed-form rates: one part that never moves."""

    def __init__(self) -> None:
        super().__init__("still", [Part("p", ((0.0, 0.0, 1.0),))], [], Driver("p"))

    def _solve_poses(self, q):
        return {"p": np.zeros((q.size, 3))}, []


def test_a_kind_without_rates_is_refused_by_name() -> None:
    with pytest.raises(UnsupportedError, match=r"_Still 'still'"):
        mechanism_rates(_Still(), np.zeros(3))


@pytest.mark.parametrize("kind", [Linkage, CamMechanism, ElementalMechanism, ToyMechanism, ToyAssembly])
def test_each_kind_defines_its_own_rates(kind: type) -> None:
    assert "part_rates" in vars(kind), f"{kind.__name__} inherits part_rates instead of answering for itself"


def test_base_attributes_every_mechanism_has() -> None:
    fb = FourBar(4.0, 1.0, 3.5, 3.0)
    assert (tuple(fb.stages), fb.spatial, fb.view, dict(fb.bodies), tuple(fb.notes)) == ((), False, "xy", {}, ())
    assert elemental(8).view == "xz" and not elemental(8).spatial
    assert elemental(6).spatial and elemental(9).spatial
    assert [r.number for r in ELEMENTAL.values() if r.spatial] == [6, 9]


@pytest.mark.parametrize("number", sorted(ELEMENTAL))
def test_record_rates_are_the_time_derivatives_of_its_forward_kinematics(number: int) -> None:
    """Each record's ``rates`` against central differences of its own ``forward`` along a driver motion with a
    random (non-constant) rate: ``u(t) = u0 + u1 t + u2 t^2 / 2``, samples spread over the standalone law."""
    rec = ELEMENTAL[number]
    mech = elemental(number)
    rng = np.random.default_rng(1000 + number)
    q = mech.driver.value(rng.uniform(0.0, mech.driver.period, 40))
    u0 = standalone_motion(number, mech.params, q)
    u1 = rng.uniform(-1.5, 1.5, u0.shape)
    u2 = rng.uniform(-3.0, 3.0, u0.shape)
    out1, out2, ok = rec.rates(mech.params, u0, u1, u2)

    def diffs(h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        f = {s: rec.forward(mech.params, u0 + s * h * u1 + 0.5 * (s * h) ** 2 * u2) for s in (-1, 0, 1)}
        d1 = (f[1].out - f[-1].out) / (2 * h)
        d2 = (f[1].out - 2 * f[0].out + f[-1].out) / (h * h)
        return d1, d2, f[-1].valid & f[0].valid & f[1].valid

    # Richardson: two steps cancel the h^2 term of both differences (error O(h^4))
    # (a small step for the first derivative; a larger one for the second, whose round-off grows as 1/h^2)
    (a1, _, ok_a), (b1, _, ok_b) = diffs(2e-5), diffs(1e-5)
    (_, a2, ok_c), (_, b2, ok_d) = diffs(2e-4), diffs(1e-4)
    d1, d2 = (4 * b1 - a1) / 3, (4 * b2 - a2) / 3
    good = ok & ok_a & ok_b & ok_c & ok_d
    assert good.sum() >= 30, f"#{number}: only {good.sum()} of 40 samples usable"
    scale1 = 1.0 + np.abs(d1[good]).max()
    scale2 = 1.0 + np.abs(d2[good]).max()
    assert np.abs(out1[good] - d1[good]).max() < 1e-7 * scale1
    assert np.abs(out2[good] - d2[good]).max() < 1e-5 * scale2


def test_one_motor_torque_three_doors() -> None:
    """The linkage loads torque (statics), the exact-rates torque and the differenced one are one sum: on a
    four-bar of random dimensions with a load, a spring to the ground and gravity they agree with each other
    (exactly for the first two, to the differences' truncation for the third)."""
    from planar.analysis import statics
    from planar.analysis.dynamics import inverse_dynamics_torque
    from planar.analysis.rates import motor_torque
    from planar.core.effects import Effects, Load, Spring

    rng = np.random.default_rng(20)
    crank = rng.uniform(0.5, 1.0)
    fb = FourBar(rng.uniform(3.0, 4.0), crank, rng.uniform(3.0, 4.0), rng.uniform(2.5, 3.5), coupler_point=(0.4, 0.7))
    motion = fb.run(samples_per_cycle=90)
    assert motion.t is not None and motion.valid.all()
    F = (float(rng.normal()), float(rng.normal()))
    loads_only = Effects(loads=(Load("coupler_point", F),))
    ideal, ok = statics.motor_torque(fb, motion.driver, {"coupler_point": F})
    exact, ok2 = motor_torque(fb, motion, loads_only, densities={p.name: 0.0 for p in fb.parts})
    assert ok.all() and ok2.all()
    np.testing.assert_allclose(ideal, exact, rtol=1e-10, atol=1e-10 * np.abs(exact).max())
    lossy, _ = statics.motor_torque(fb, motion.driver, {"coupler_point": F}, eta_trans=0.8)
    np.testing.assert_allclose(lossy, np.where(exact >= 0, exact / 0.8, exact * 0.8), rtol=1e-10, atol=1e-12)
    full = Effects(
        gravity=(0.0, -9.81),
        loads=(Load("coupler_point", F),),
        springs=(Spring(fb.parts[-1].name, next(p.name for p in fb.parts if p.ground), 5.0),),
    )
    tau, ok3 = motor_torque(fb, motion, full)
    ref = inverse_dynamics_torque(fb, motion.t, full)
    assert ok3.all()
    np.testing.assert_allclose(tau, ref, rtol=1e-5, atol=1e-6 * np.abs(ref).max())
