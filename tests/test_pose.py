"""Typed task-space I/O (SPEC §16): a PoseTarget in place of the flat (24,)
array, and a step's quantities by name."""

from __future__ import annotations

import numpy as np
import pytest

import adaptimp
from adaptimp import CartesianStep, ConfigError, PoseTarget


def test_a_pose_target_is_the_flat_target_it_replaces() -> None:
    R = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    t = PoseTarget(p=[0.4, 0.1, 0.3], dp=[0.0, 0.2, 0.0], R=R, w=[0.0, 0.0, 0.5])
    flat = adaptimp.cartesian.pose_target([0.4, 0.1, 0.3], [0.0, 0.2, 0.0], None, R, [0, 0, 0.5])
    assert np.array_equal(t.flat, flat)
    assert PoseTarget.from_flat(flat) == t
    assert np.array_equal(PoseTarget.at([1.0, 2.0, 3.0]).R, np.eye(3))
    with pytest.raises(AttributeError):
        t.p = np.zeros(3)  # type: ignore[misc]
    assert not t.p.flags.writeable


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"p": [0.0, 0.0]}, "p must have shape (3,), got (2,)"),
        ({"p": [0.0, 0.0, 0.0], "R": np.eye(3).ravel()}, "R must have shape (3, 3), got (9,)"),
        ({"p": [0.0, float("nan"), 0.0]}, "p[1] = nan is not finite"),
        ({"p": [0.0, 0.0, 0.0], "w": [0.0, 0.0, float("inf")]}, "w[2] = inf is not finite"),
    ],
)
def test_a_bad_pose_target_is_refused_by_name(kw: dict[str, object], message: str) -> None:
    with pytest.raises(ConfigError) as e:
        PoseTarget(**kw)  # type: ignore[arg-type]
    assert str(e.value) == message


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"p": "abc"}, "p must be real numbers, got str 'abc'"),
        ({"p": [True, False, True]}, "p must hold real numbers, got an array of dtype bool"),
        ({"p": ["0.1", "0", "0"]}, "p must hold real numbers, got an array of dtype <U3"),
    ],
)
def test_a_pose_target_of_another_type_is_refused_by_name(
    kw: dict[str, object], message: str
) -> None:
    """Text and bools were read as numbers ("0.1" as 0.1, True as 1)."""
    with pytest.raises(TypeError) as e:
        PoseTarget(**kw)  # type: ignore[arg-type]
    assert str(e.value) == message


def _two_impedances() -> tuple[adaptimp.cartesian.CartesianImpedance, ...]:
    chain = adaptimp.Chain(
        [
            {"kind": "revolute", "axis": [0, 0, 1]},
            {"kind": "revolute", "axis": [0, 1, 0], "origin": {"xyz": [0, 0, 0.3]}},
            {"kind": "revolute", "axis": [0, 1, 0], "origin": {"xyz": [0.3, 0, 0]}},
        ],
        {"xyz": [0.25, 0, 0]},
    )
    q0 = np.array([0.1, 0.4, -0.8])
    return tuple(adaptimp.cartesian.CartesianImpedance(chain, Ts=1e-3, q0=q0) for _ in range(2))


def test_a_step_takes_a_pose_target_as_it_takes_its_parts() -> None:
    a, b = _two_impedances()
    p0 = a.chain.fk(a.q0)[:3, 3]
    for k in range(5):
        p = p0 + np.array([0.001 * k, 0.0, 0.0])
        ra = a.step(p, [0.1, 0.0, 0.0], wrench=[0.0, 0.0, 1.0])
        rb = b.step(
            target=PoseTarget(p=p, dp=[0.1, 0.0, 0.0], R=a.held_rotation), wrench=[0.0, 0.0, 1.0]
        )
        for x, y in zip(ra, rb):
            assert np.array_equal(x, y)
    out = a.output
    assert isinstance(out, CartesianStep)
    assert np.array_equal(out.p_d, a.last("p_d"))
    assert np.array_equal(out.q_d, ra[0])
    assert out.R_d.shape == (3, 3)
    assert out.error.shape == (6,)
    with pytest.raises(TypeError, match="not both"):
        a.step(p0, target=PoseTarget(p=p0))
