"""Figures: the right panels, labels with units, the wall and the limits drawn; files written."""

from __future__ import annotations

import numpy as np
import pytest

import adaptimp
from adaptimp import SimResult
from adaptimp._plot import compare

PNG = b"\x89PNG\r\n\x1a\n"
pytestmark = pytest.mark.usefixtures("close_figures")


def labels(fig) -> list[str]:
    return [ax.get_ylabel() for ax in fig.axes] + [ax.get_xlabel() for ax in fig.axes]


@pytest.mark.parametrize("kind", adaptimp.PLOT_KINDS)
@pytest.mark.parametrize("case", adaptimp.CASES)
def test_every_kind_is_written_as_a_nonempty_png(
    runs: dict[str, SimResult], case: str, kind: str, tmp_path
) -> None:
    fig = runs[case].plot(kind)
    path = tmp_path / f"{case}_{kind}.png"
    fig.savefig(path, dpi=80)
    data = path.read_bytes()
    assert data.startswith(PNG)
    assert len(data) > 20_000
    assert any("time t (s)" in label for label in labels(fig))


def test_tracking_draws_q_xc_xd_and_the_wall(runs: dict[str, SimResult]) -> None:
    fig = runs["sf"].plot("tracking")
    top, bottom = fig.axes[:2]
    assert top.get_ylabel() == "joint 1: q1 (rad)"
    assert bottom.get_ylabel() == "joint 2: q2 (rad)"
    lines = {line.get_label(): line for line in top.get_lines()}
    assert set(lines) == {
        "xc, commanded",
        "xd, compliant reference",
        "q, arm",
        "wall at 0.2 rad",
    }
    np.testing.assert_array_equal(lines["q, arm"].get_ydata(), runs["sf"].q[:, 0])
    assert list(lines["wall at 0.2 rad"].get_ydata()) == [0.2, 0.2]
    # One legend for the figure, outside the axes.
    assert len(fig.legends) == 1
    assert top.get_legend() is None


def test_free_space_has_no_wall() -> None:
    fig = adaptimp.simulate("pd", T=0.1, wall=None).plot("tracking")
    assert not any("wall" in line.get_label() for line in fig.axes[0].get_lines())


def test_errors_split_the_settling_transient_from_the_rest(runs: dict[str, SimResult]) -> None:
    res = runs["of"]
    fig = res.plot("errors")
    assert len(fig.axes) == 4
    assert fig.axes[0].get_ylabel() == "joint 1: z1,1 (rad)"
    rms = res.metrics["rms_z1_joint_after2"]
    assert fig.axes[1].get_title(loc="left") == f"t ≥ 2 s: RMS = {rms[0]:.3g} rad"
    early, late = fig.axes[0].get_lines()[-1], fig.axes[1].get_lines()[-1]
    assert np.max(early.get_xdata()) < 2.0 <= np.min(late.get_xdata())
    assert len(early.get_xdata()) + len(late.get_xdata()) == res.rows


def test_torques_draw_the_limits_and_clip_windup(runs: dict[str, SimResult]) -> None:
    res = runs["sf"]
    fig = res.plot("torques")
    ax1 = fig.axes[0]
    assert ax1.get_ylabel() == "τ1 (N m)"
    limits = sorted(line.get_ydata()[0] for line in ax1.get_lines() if line.get_linestyle() == "--")
    assert limits == [-17.0, 17.0]
    peak = res.metrics["peak_abs_tau"][0]
    if peak > 1.6 * 17.0:
        assert ax1.get_ylim() == pytest.approx((-1.6 * 17.0, 1.6 * 17.0))
        assert f"peak |τ| = {peak:.4g} N m" in ax1.get_title(loc="left")


def test_comparison_figure_has_one_line_per_case_and_joint(
    runs: dict[str, SimResult], tmp_path
) -> None:
    fig = compare(list(runs.values()))
    for ax in fig.axes:
        assert len(ax.get_lines()) == 3
        assert ax.get_yscale() == "log"
        assert ax.get_ylabel().endswith("(rad)")
    fig.savefig(tmp_path / "comparison.png", dpi=80)
    assert (tmp_path / "comparison.png").stat().st_size > 20_000


def test_a_mujoco_run_names_each_joint_and_its_unit() -> None:
    """A run on a URDF arm labels each joint by its name in the model, with its
    unit (issue 45, finding 7: they were x1 … x5); a Cartesian run the world
    axes, in metres."""
    from pathlib import Path

    from adaptimp import mujoco as amj

    with pytest.warns(UserWarning, match="effort limit"):
        plant = amj.Plant(Path(__file__).resolve().parent / "data" / "hobby_arm.urdf")
    names = ["base_yaw", "shoulder_pitch", "elbow_pitch", "wrist_pitch", "wrist_roll"]
    assert plant.joint_names == names
    res = amj.simulate("sf", plant, T=0.05)
    assert res.params["joints"] == names
    want = {
        "tracking": [f"{n} (rad)" for n in names],
        "errors": [f"z1, {n} (rad)" for n in names],
        "torques": [f"τ, {n} (N m)" for n in names],
    }
    for kind, ylabels in want.items():
        assert [ax.get_ylabel() for ax in res.plot(kind).axes] == ylabels, kind
    task = amj.cartesian_task(plant)
    cart = amj.simulate("pd", plant, T=0.05, task=task)
    assert [ax.get_ylabel() for ax in cart.plot("tracking").axes] == ["x (m)", "y (m)", "z (m)"]
    assert [ax.get_ylabel() for ax in cart.plot("errors").axes] == [
        "z1, x (m)",
        "z1, y (m)",
        "z1, z (m)",
    ]
    assert [ax.get_ylabel() for ax in cart.plot("torques").axes] == want["torques"]
