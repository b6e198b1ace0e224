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
