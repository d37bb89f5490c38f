"""Plots (PNG). matplotlib is imported here only, with the non-interactive Agg backend."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from linearize import OperatingPoint

__all__ = ["plot_lidar_evaluation", "plot_cp_surface", "plot_operating_schedule", "plot_lidar_coherence",
           "plot_scan_pattern", "plot_cs_ellipses", "plot_psd_comparison", "plot_design",
           "assess_plots", "plot_pareto", "plot_wind_condition", "plot_verify"]


def save_figure(fig, path: str | Path) -> Path:  # type: ignore[no-untyped-def]
    """Lay out, write the PNG and release the figure."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, bbox_inches="tight")
    plt.close(fig)
    return out


def pyplot():  # type: ignore[no-untyped-def]
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_cp_surface(tsr: np.ndarray, pitch_deg: np.ndarray, cp: np.ndarray, path: str | Path,
                    title: str = "", optimum: tuple[float, float, float] | None = None) -> Path:
    """Contour plot of C_P(lambda, beta) with its maximum marked; returns the PNG path.

    Parameters
    ----------
    tsr : (n_tsr,) ndarray
        Tip-speed ratios [-].
    pitch_deg : (n_pitch,) ndarray
        Pitch angles [deg].
    cp : (n_pitch, n_tsr) ndarray
        Power coefficient [-].

    path : str or Path
        The PNG file.
    title : str
        Title (default a generic one).
    optimum : (float, float, float), optional
        The computed optimum (tip-speed ratio, pitch [deg], C_P) to mark and label; default
        the grid's largest value.

    Returns
    -------
    Path
        The PNG file.
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 5.0), dpi=120)
    shown = np.clip(cp, 0.0, None)
    step = 0.02 if shown.max() > 0.1 else 0.002
    top = step * math.ceil(max(float(shown.max()), 1e-3) / step - 1e-9)
    levels = np.linspace(0.0, top, int(round(top / step)) + 1)
    cs = ax.contourf(tsr, pitch_deg, shown, levels=levels, cmap="viridis")
    ax.contour(tsr, pitch_deg, shown, levels=[0.1, 0.2, 0.3, 0.4, 0.45], colors="w",
               linewidths=0.6)
    if optimum is None:
        i, j = np.unravel_index(int(np.argmax(cp)), cp.shape)
        optimum = (float(tsr[j]), float(pitch_deg[i]), float(cp[i, j]))
    lam, beta, cp_max = optimum
    ax.plot(lam, beta, "r*", ms=12,
            label=f"C_P max {cp_max:.3f} at lambda {lam:.2f}, pitch {beta:.1f} deg")
    bar = fig.colorbar(cs, ax=ax, label="C_P [-]")
    from matplotlib.ticker import MaxNLocator

    bar.set_ticks(MaxNLocator(6, steps=[1, 2, 5, 10]).tick_values(0.0, top))
    bar.ax.set_ylim(0.0, top)
    ax.set_xlabel("tip-speed ratio lambda [-]")
    ax.set_ylabel("collective pitch [deg]")
    ax.set_title(title or "Power coefficient C_P(lambda, pitch)")
    ax.legend(loc="upper right", fontsize=8)
    return save_figure(fig, path)


def plot_operating_schedule(points: Sequence[OperatingPoint], path: str | Path,
                            title: str = "", rated_wind_mps: float | None = None) -> Path:
    """Four panels against wind speed: power, rotor speed, pitch, thrust and generator torque.

    Parameters
    ----------
    points : sequence of OperatingPoint
        The steady operating points.
    path : str or Path
        The PNG file.
    title : str
        Title.
    rated_wind_mps : float, optional
        The computed rated wind speed, marked on every panel [m/s] (default: the first
        region-3 point's wind).

    Returns
    -------
    Path
        The PNG file.
    """
    plt = pyplot()
    v = np.array([p.wind_mps for p in points])
    fig, axs = plt.subplots(2, 2, figsize=(9.0, 6.5), dpi=120, sharex=True)
    axs[0, 0].plot(v, [p.power / 1e6 for p in points], "o-", ms=3, label="electrical")
    axs[0, 0].plot(v, [p.aero_power / 1e6 for p in points], "s--", ms=3, label="aerodynamic")
    axs[0, 0].set_ylabel("power [MW]")
    axs[0, 0].legend(fontsize=8)
    axs[0, 1].plot(v, [p.rotor_speed_rpm for p in points], "o-", ms=3)
    axs[0, 1].set_ylabel("rotor speed [rpm]")
    axs[1, 0].plot(v, [p.pitch_deg for p in points], "o-", ms=3)
    axs[1, 0].set_ylabel("pitch [deg]")
    ax2 = axs[1, 1]
    ax2.plot(v, [p.thrust / 1e3 for p in points], "o-", ms=3, color="C0")
    ax2.set_ylabel("rotor thrust [kN]", color="C0")
    ax3 = ax2.twinx()
    ax3.plot(v, [p.gen_torque / 1e3 for p in points], "s--", ms=3, color="C3")
    ax3.set_ylabel("generator torque [kN m]", color="C3")
    for ax in axs[1]:
        ax.set_xlabel("hub-height wind speed [m/s]")
    for ax in axs.flat:
        ax.grid(alpha=0.3)
    if rated_wind_mps is None:
        rated_wind_mps = next((p.wind_mps for p in points if p.region == "3"), None)
    if rated_wind_mps is not None:
        for ax in axs.flat:
            ax.axvline(rated_wind_mps, color="0.6", lw=0.8, ls=":")
        axs[0, 0].annotate(f"rated {rated_wind_mps:.2f} m/s", (rated_wind_mps, 0.05),
                           xycoords=("data", "axes fraction"), fontsize=7, color="0.4",
                           xytext=(3, 0), textcoords="offset points")
    fig.suptitle(title or "Steady operating schedule")
    return save_figure(fig, path)


def plot_lidar_coherence(f: np.ndarray, gamma2: np.ndarray, bandwidth_hz: float,
                         mean_speed: float, path: str | Path) -> Path:
    """Magnitude-squared coherence of the LIDAR estimate with the later blade wind, per blade.

    Parameters
    ----------
    f : (n_f,) ndarray
        [Hz]
    gamma2 : (n_f, 3) ndarray
        [-]

    Returns
    -------
    Path
        The PNG file.
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.0, 4.2), dpi=120)
    for i in range(gamma2.shape[1]):
        ax.semilogx(f[1:], gamma2[1:, i], lw=1.0, label=f"blade {i + 1}")
    ax.axhline(0.5, color="0.4", ls=":", lw=0.8)
    ax.axvline(bandwidth_hz, color="C3", ls="--", lw=1.0,
               label=f"bandwidth {bandwidth_hz:.2f} Hz (k = "
                     f"{2 * np.pi * bandwidth_hz / mean_speed:.3f} rad/m)")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("coherence gamma^2 [-]")
    ax.set_ylim(0, 1.02)
    ax.set_title("LIDAR preview vs wind at the blade (75 % span)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    return save_figure(fig, path)


def plot_scan_pattern(beam_azimuth_rad: np.ndarray, blade_azimuth_rad: np.ndarray,
                      radius: float, rotor_radius: float, path: str | Path) -> Path:
    """Measurement points and blade positions in the rotor plane seen from upwind.

    Parameters
    ----------
    beam_azimuth_rad : (n_t, 3) ndarray
        Azimuth of each beam's focus [rad] (0 = up, clockwise seen from upwind).
    blade_azimuth_rad : (n_t,) ndarray
        Azimuth of blade 1 [rad].

    Returns
    -------
    Path
        The PNG file.
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(5.5, 5.5), dpi=120)
    th = np.linspace(0, 2 * np.pi, 200)
    ax.plot(rotor_radius * np.sin(th), rotor_radius * np.cos(th), color="0.6", lw=0.8)
    # seen from upwind, +y (left looking downwind) is on the right: plot -y as x
    for i in range(beam_azimuth_rad.shape[1]):
        a = beam_azimuth_rad[:, i]
        ax.plot(radius * np.sin(a), radius * np.cos(a), ".", ms=2, alpha=0.4,
                label=f"beam {i + 1}")
    a0 = blade_azimuth_rad[0] + 2 * np.pi * np.arange(3) / 3
    for i, a in enumerate(a0):
        ax.plot([0, rotor_radius * np.sin(a)], [0, rotor_radius * np.cos(a)], lw=2,
                color=f"C{i}")
        b = beam_azimuth_rad[0, i]
        ax.plot(radius * np.sin(b), radius * np.cos(b), "o", ms=8, mfc="none", color=f"C{i}")
    ax.set_aspect("equal")
    ax.set_xlabel("lateral, seen from upwind [m]")
    ax.set_ylabel("vertical from hub [m]")
    ax.set_title("CW LIDAR scan: foci lead their blades by omega T_p")
    ax.legend(fontsize=8, loc="lower right")
    return save_figure(fig, path)


def plot_cs_ellipses(items: list[tuple[str, Any, np.ndarray, np.ndarray]], path: str | Path,
                     load_label: str = "tower-base fore-aft moment [MN m]",
                     case: str = "") -> Path:
    """Do et al. (2020) fig. 4: load-power samples and their 95 % ellipses for several runs.

    ``items``: (label, CSMeasures, load samples, power samples) per run.

    Parameters
    ----------
    items : list of (str, CSMeasures, (n_t,) ndarray, (n_t,) ndarray)
        Label, measures, load samples [N m] and power samples [W] per run.
    path : str or Path
        The PNG file.
    load_label : str
        Axis label of the load.
    case : str
        The case the runs are of (turbine, wind, turbulence, seed, window), in the title.

    Returns
    -------
    Path
        The PNG file.
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.0, 5.6), dpi=120)
    for k, (label, cs, x, y) in enumerate(items):
        step = max(1, len(x) // 3000)
        ax.plot(np.asarray(x)[::step] / 1e6, np.asarray(y)[::step] / 1e6, ".", ms=1.5,
                alpha=0.25, color=f"C{k}")
        ex, ey = cs.ellipse()
        ax.plot(ex / 1e6, ey / 1e6, color=f"C{k}", lw=1.6,
                label=f"{label}: CS1 {cs.cs1 / 1e6:.2f} MN m, CS2 {cs.cs2 / 1e6:.3f} MW, "
                      f"CS5 {cs.cs5:.2g} deg")
        ax.plot(cs.cs3 / 1e6, cs.cs4 / 1e6, "+", color=f"C{k}", ms=10)
    ax.set_xlabel(load_label)
    ax.set_ylabel("generator power [MW]")
    ax.set_title("Covariance ellipses (95 %, s = 5.99), Do et al. 2020"
                 + (f"\n{case}" if case else ""), fontsize=9)
    # CS5 is the major axis's angle in the samples' own units (eq. 26): the axes here are
    # scaled apart, so the drawn tilt is larger than that angle. Legend and note below the
    # axes, off the samples.
    leg = ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=1,
                    frameon=False, title="CS5: major axis to load axis in N m and W (Do et "
                    "al. eq. 26); axes not to the same scale", title_fontsize=7)
    leg.get_title().set_color("0.35")
    ax.grid(alpha=0.3)
    fig.subplots_adjust(bottom=0.30)
    return save_figure(fig, path)


def plot_psd_comparison(items: list[tuple[str, np.ndarray, np.ndarray]], rotor_hz: float,
                        path: str | Path, ylabel: str, case: str = "") -> Path:
    """PSDs of one channel for several runs, with 1P, 3P, 6P marked.

    Parameters
    ----------
    items : list of (str, ndarray, ndarray)
        Label, frequencies [Hz] and PSD per run.
    rotor_hz : float
        Rotor frequency 1P [Hz].
    path : str or Path
        The PNG file.
    ylabel : str
        Axis label of the PSD.
    case : str
        The case the runs are of, in the title.

    Returns
    -------
    Path
        The PNG file.
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.0, 4.4), dpi=120)
    for label, f, p in items:
        ax.loglog(f[1:], p[1:], lw=1.0, label=label)
    for n in (1, 3, 6):
        ax.axvline(n * rotor_hz, color="0.5", ls=":", lw=0.8)
        # in axes coordinates a little below the frame: the labels stay inside it
        ax.text(n * rotor_hz, 0.97, f"{n}P", fontsize=7, va="top", ha="left",
                transform=ax.get_xaxis_transform())
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(ylabel)
    if case:
        ax.set_title(case, fontsize=9)
    ax.legend(fontsize=8, loc="lower left")
    ax.grid(alpha=0.3, which="both")
    return save_figure(fig, path)


def assess_plots(runs: Sequence[tuple[str, np.ndarray, dict[str, np.ndarray]]],
                 out_dir: str | Path, case: str = "") -> list[str]:
    """CS ellipses (Do et al. fig. 4) and flap-moment PSDs of several runs, as PNG.

    Parameters
    ----------
    runs : sequence of (str, (n_t,) ndarray, dict)
        Label, time [s] and channels of each run.
    out_dir : str or Path
        Folder of ``cs_ellipses.png`` and ``psd_flap_moment_1.png`` (created).
    case : str
        The case the runs are of (turbine, wind, turbulence, seed, window), in the titles.

    Returns
    -------
    list of str
        The files written.
    """
    from mpc_wt.assessment.performance import cs_measures, psd

    d = Path(out_dir)
    d.mkdir(parents=True, exist_ok=True)
    made = []
    items = [(name, cs_measures(c["tower_base_fa_moment"], c["gen_power"]),
              c["tower_base_fa_moment"], c["gen_power"]) for name, _, c in runs
             if "tower_base_fa_moment" in c and "gen_power" in c]
    if items:
        made.append(str(plot_cs_ellipses(items, d / "cs_ellipses.png", case=case)))
    spectra = []
    frot = 0.2
    for name, t, c in runs:
        if "flap_moment_1" in c:
            dt = float(np.median(np.diff(t)))
            f, p = psd(c["flap_moment_1"], 1 / dt)
            spectra.append((name, f, p))
            if "rotor_speed" in c:
                frot = float(c["rotor_speed"].mean()) / (2 * math.pi)
    if spectra:
        made.append(str(plot_psd_comparison(spectra, frot, d / "psd_flap_moment_1.png",
                                             "flap moment PSD [(N m)^2/Hz]", case=case)))
    return made


def plot_design(doc: dict[str, Any], path: str | Path) -> Path:
    """The gains of a design document as PNG, as its kind's table function asked
    (:func:`mpc_wt.io.gain_tables.document`'s ``plot``): the columns it names against wind
    speed, else the largest gains of ``K`` against wind speed or the vertex.

    Parameters
    ----------
    doc : dict
        A gain-table document (:mod:`mpc_wt.io.gain_tables`).
    path : str or Path
        The PNG file.

    Returns
    -------
    Path
        ``path``.
    """
    plt = pyplot()
    s = doc["schedule"]
    rows = np.asarray(s["rows"], dtype=float)
    x = rows[:, 0]
    fig, ax = plt.subplots(figsize=(7, 4))
    hint = doc.get("plot") or {}
    by_vertex = hint.get("x") == "vertex"
    if hint.get("columns"):
        scale = float(hint.get("scale", 1.0))
        for c in hint["columns"]:
            ax.plot(x, scale * rows[:, s["columns"].index(c)], "o-", label=c)
        ax.set_ylabel(hint.get("label", "gain"))
    else:
        k = np.asarray(doc["matrices"]["K"]["data"])
        m = doc["matrices"]["K"]
        flat = k.reshape(k.shape[0], -1)
        big = np.argsort(-np.abs(flat).max(axis=0))[:6]
        for j in big:
            lab = f"K[{m['rows'][j // len(m['cols'])]}, {m['cols'][j % len(m['cols'])]}]"
            v = flat[:, j] / max(np.abs(flat[:, j]).max(), 1e-300)
            ax.plot(np.arange(len(x)) if by_vertex else x, v, "o-", label=lab)
        ax.set_ylabel("gain / its largest magnitude [-]")
    ax.set_xlabel("vertex index (wind outer, power reduction inner)" if by_vertex
                  else "wind speed [m/s]")
    ax.set_title(f"{hint.get('title', doc['kind'] + ' gains')}, {doc['turbine']}", fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    return save_figure(fig, path)


def plot_comparison(runs: Sequence[tuple[str, np.ndarray, dict[str, np.ndarray]]],
                    path: str | Path, window_s: float = 120.0, case: str = "") -> list[str]:
    """Electrical power, rotor speed, collective pitch, blade-1 flap moment and tower-base
    fore-aft moment of several runs, stacked panels over the last ``window_s`` of the runs (a
    readable stretch), each run's mean and standard deviation over the samples given in its
    legend, beside the panel.

    Parameters
    ----------
    runs : sequence of (str, (n_t,) ndarray, dict)
        Label, time [s] and channels of each run.
    path : str or Path
        The PNG file.
    window_s : float
        Length of the stretch shown [s] (the whole run when shorter).
    case : str
        The case the runs are of (turbine, wind, turbulence, seed), in the title.

    Returns
    -------
    list of str
        The file written.
    """
    plt = pyplot()
    panels = (("gen_power", 1e-6, "power", "MW"),
              ("rotor_speed", 30 / np.pi, "rotor speed", "rpm"),
              ("pitch_1", 180 / np.pi, "pitch", "deg"),
              ("flap_moment_1", 1e-6, "flap moment, blade 1", "MN m"),
              ("tower_base_fa_moment", 1e-6, "tower-base fore-aft moment", "MN m"))
    shown = [p for p in panels if any(p[0] in cols for _, _, cols in runs)]
    fig, axes = plt.subplots(len(shown), 1, figsize=(12, 1.9 * len(shown) + 0.9), sharex=True,
                             squeeze=False)
    t_end = max(float(t[-1]) for _, t, _ in runs)
    t0 = max(min(float(t[0]) for _, t, _ in runs), t_end - window_s)
    for ax, (ch, scale, name, unit) in zip(axes[:, 0], shown):
        for label, t, cols in runs:
            if ch not in cols:
                continue
            x = np.asarray(cols[ch]) * scale
            keep = t >= t0
            ax.plot(t[keep], x[keep], lw=0.8,
                    label=f"{label}: {x.mean():#.3g} ± {x.std():#.2g} {unit}")
        ax.set_ylabel(f"{name} [{unit}]", fontsize=8)
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7, frameon=False)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    axes[-1, 0].set_xlim(t0, t_end)
    a = min(float(t[0]) for _, t, _ in runs)
    fig.suptitle((f"{case}; " if case else "") + f"last {t_end - t0:.0f} s shown; legend: "
                 f"mean ± std over {a:g}-{t_end:g} s", fontsize=9)
    fig.subplots_adjust(right=0.72)
    p = save_figure(fig, path)
    return [str(p)]


def _zoom(ax: Any, pts: np.ndarray, extra: Sequence[Any]) -> None:
    """Axis limits over the points up to 1.5x their 80th percentile (and 1 and ``extra``, per
    axis): a few diverging designs would otherwise squash the front into a corner."""
    if pts.shape[0] < 3:
        return
    for col, setter in ((0, ax.set_xlim), (1, ax.set_ylim)):
        v = np.concatenate([pts[:, col], [1.0], [e for e in extra[col:col + 1]
                                                 if e is not None]])
        hi = min(float(v.max()), 1.5 * float(np.percentile(v, 80)))
        lo = float(v.min())
        pad = 0.05 * (hi - lo) if hi > lo else 0.05
        setter(lo - pad, hi + pad)


def plot_pareto(metrics: Sequence[dict[str, float]], feasible: Sequence[bool],
                xs: Sequence[str], ys: Sequence[str], fronts: dict[tuple[str, str], Any],
                bounds: dict[str, float], marks: dict[str, dict[str, float]],
                path: str | Path, title: str = "", absolute: Any = ()) -> Path:
    """A tuning's trials: each measure in ``ys`` (rows) against each in ``xs`` (columns),
    feasible and infeasible trials, the non-dominated front of each pair, the bounds and the
    marked designs (``hand-set``: black diamond, ``best``: red star).

    Parameters
    ----------
    metrics : sequence of dict
        Each completed trial's measures (ratios to the reference, or per-case values).
    feasible : sequence of bool
    xs, ys : sequence of str
        Measures on the horizontal and vertical axes.
    fronts : dict
        (y, x) -> indices of the front's trials, in order along x.
    bounds : dict
        Measure -> upper bound (a dashed line where it is an x).
    marks : dict
        ``hand-set`` / ``best`` -> measures.
    path : str or Path
    title : str
    absolute : collection of str
        Measures that are not ratios (labelled without "/ reference").

    Returns
    -------
    Path
    """
    plt = pyplot()
    fig, axes = plt.subplots(len(ys), len(xs), figsize=(4.6 * len(xs), 3.4 * len(ys)),
                             squeeze=False)
    ok = np.asarray(feasible, bool)
    style = {"hand-set": ("D", "k", 6), "best": ("*", "tab:red", 13)}
    for r, y in enumerate(ys):
        for c, x in enumerate(xs):
            ax = axes[r][c]
            pts = np.array([[m.get(x, math.nan), m.get(y, math.nan)] for m in metrics], float)
            ax.scatter(pts[~ok, 0], pts[~ok, 1], c="0.7", s=16, label="infeasible")
            ax.scatter(pts[ok, 0], pts[ok, 1], c="tab:blue", s=16, label="feasible")
            front = np.asarray(fronts.get((y, x), []), int)
            if front.size >= 2:
                ax.plot(pts[front, 0], pts[front, 1], "-", c="tab:orange", lw=1.2,
                        label="Pareto front")
            if x in bounds:
                ax.axvline(bounds[x], ls="--", c="k", lw=0.8, label="bound")
            for name, m in marks.items():
                if x in m and y in m:
                    mk, col, ms = style.get(name, ("o", "tab:green", 7))
                    ax.plot(m[x], m[y], mk, c=col, ms=ms, label=name)
            ax.axhline(1.0, c="0.5", lw=0.6)
            hand = marks.get("hand-set", {})
            _zoom(ax, pts[np.all(np.isfinite(pts), axis=1)], [hand.get(x), hand.get(y)])
            ax.set_xlabel(x if x in absolute else f"{x} / reference")
            ax.set_ylabel(y if y in absolute else f"{y} / reference")
            ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=7)
    fig.suptitle(title)
    return save_figure(fig, path)


def plot_wind_condition(field: Any, path: str | Path) -> Path:
    """An IEC wind condition over time (:func:`lidar.iec_field`): the speed at the hub and at
    the top, bottom and lateral edges of the grid, and the direction at the hub.

    Parameters
    ----------
    field : lidar.WindField
        The field.
    path : str or Path
        The PNG.

    Returns
    -------
    Path
        The file written.
    """
    plt = pyplot()
    j, k = int(np.argmin(np.abs(field.y))), int(np.argmin(np.abs(field.z - field.hub_height)))
    speed = np.hypot(field.u, field.v)
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    t = np.asarray(field.t, float)
    yh, zh = np.zeros_like(t), np.full_like(t, field.hub_height)
    hu, hv = field.sample(t, yh, zh, "u"), field.sample(t, yh, zh, "v")
    a1.plot(t, np.hypot(hu, hv), label="hub", lw=1.2)
    for lab, jj, kk in (("top", j, -1), ("bottom", j, 0), ("left (+y)", -1, k),
                        ("right (-y)", 0, k)):
        a1.plot(t, speed[:, jj, kk], label=lab, lw=0.8)
    a1.set_ylabel("speed [m/s]")
    a1.legend(fontsize=8, ncol=5)
    m = field.meta
    a1.set_title(f"IEC 61400-1 {m.get('condition', '').upper()}, class "
                 f"{m.get('turbine_class', '?')}{m.get('turbulence_class', '')}, "
                 f"V_hub {field.mean_speed:g} m/s")
    a2.plot(t, np.degrees(np.arctan2(hv, hu)))
    a2.set_ylabel("direction at the hub [deg]")
    a2.set_xlabel("t [s]")
    for ax in (a1, a2):
        ax.grid(alpha=0.3)
    return save_figure(fig, path)


def _grouped_bars(ax: Any, cats: Sequence[str], series: dict[str, list[float | None]]) -> None:
    """Bars of several series (legend labels) over categories; None leaves a gap."""
    n = max(1, len(series))
    w = 0.8 / n
    x = np.arange(len(cats))
    for i, (lab, vals) in enumerate(series.items()):
        v = np.array([np.nan if a is None else a for a in vals], float)
        ax.bar(x + (i - (n - 1) / 2) * w, v, w, label=lab, color=f"C{i}")
    ax.set_xticks(x)
    ax.set_xticklabels(cats, fontsize=7, rotation=30, ha="right")
    ax.grid(alpha=0.3, axis="y")


def plot_ultimate(rows: Sequence[dict[str, Any]], path: str | Path) -> Path:
    """Design loads per DLC and controller, one panel per channel (maximum above zero, minimum
    below; :func:`mpc_wt.campaign.signoff.ultimate_rows`).

    Parameters
    ----------
    rows : sequence of dict
        Ultimate rows (``controller``, ``dlc``, ``channel``, ``design_max``, ``design_min``).
    path : str or Path
        The PNG.

    Returns
    -------
    Path
        The file written.
    """
    plt = pyplot()
    rows = [r for r in rows if r["design_max"] is not None or r["design_min"] is not None]
    chans = list(dict.fromkeys(r["channel"] for r in rows))
    ctls = list(dict.fromkeys(r["controller"] for r in rows))
    dlcs = list(dict.fromkeys(r["dlc"] for r in rows))
    nc = min(3, len(chans))
    nr = math.ceil(len(chans) / nc)
    fig, axs = plt.subplots(nr, nc, figsize=(4.6 * nc, 3.2 * nr), dpi=110, squeeze=False)
    for ax, ch in zip(axs.flat, chans):
        sel = [r for r in rows if r["channel"] == ch]
        big = max(abs(r[k] or 0.0) for r in sel for k in ("design_max", "design_min")) > 1e5
        scale, unit = (1e-6, " [M]") if big else (1.0, "")
        for side in ("design_max", "design_min"):
            _grouped_bars(ax, dlcs, {c: [next((None if r[side] is None else r[side] * scale
                                               for r in sel if r["controller"] == c
                                               and r["dlc"] == d), None) for d in dlcs]
                                     for c in ctls})
        ax.axhline(0.0, color="k", lw=0.6)
        ax.set_title(f"{ch}{unit}", fontsize=8)
        ax.set_xlabel("DLC", fontsize=8)
    handles, labels = axs.flat[0].get_legend_handles_labels()
    axs.flat[0].legend(handles[:len(ctls)], labels[:len(ctls)], fontsize=7)
    for ax in list(axs.flat)[len(chans):]:
        ax.set_visible(False)
    fig.suptitle("Design loads per DLC (partial safety factors applied)", fontsize=9)
    return save_figure(fig, path)


def plot_signoff(signoff: Sequence[dict[str, Any]], governing: Sequence[dict[str, Any]],
                 path: str | Path) -> Path:
    """A controller sign-off at a glance: the governing design load per channel against the
    reference's, the largest rotor speed per DLC against rated (with the overspeed limit) and
    the largest pitch rate per DLC against the actuator's limit.

    Parameters
    ----------
    signoff : sequence of dict
        :func:`mpc_wt.campaign.signoff.signoff_rows`.
    governing : sequence of dict
        :func:`mpc_wt.campaign.signoff.governing_rows`.
    path : str or Path
        The PNG.

    Returns
    -------
    Path
        The file written.
    """
    plt = pyplot()
    ctls = list(dict.fromkeys(r["controller"] for r in signoff))
    dlcs = list(dict.fromkeys(r["dlc"] for r in signoff))
    chans = list(dict.fromkeys(r["channel"] for r in governing))
    fig, (a1, a2, a3) = plt.subplots(3, 1, figsize=(9, 10), dpi=110)

    def pick(rows: Sequence[dict[str, Any]], key: str, by: str, cats: list[str]
             ) -> dict[str, list[float | None]]:
        return {c: [next((r.get(key) for r in rows if r["controller"] == c and r[by] == d),
                         None) for d in cats] for c in ctls}

    _grouped_bars(a1, chans, pick(governing, "change_pct", "channel", chans))
    a1.axhline(0.0, color="k", lw=0.6)
    a1.set_ylabel("governing design load\nchange [%]")
    a1.legend(fontsize=7, ncol=min(5, len(ctls)))
    _grouped_bars(a2, dlcs, pick(signoff, "rotor_speed_max_rel", "dlc", dlcs))
    lims = [r["overspeed_limit_rel"] for r in signoff if r.get("overspeed_limit_rel")]
    if lims:
        a2.axhline(min(lims), color="r", ls="--", lw=1, label="overspeed limit")
    a2.set_ylim(bottom=0.9)
    a2.set_ylabel("rotor speed max / rated")
    _grouped_bars(a3, dlcs, pick(signoff, "pitch_rate_max_rel", "dlc", dlcs))
    a3.axhline(1.0, color="r", ls="--", lw=1)
    a3.set_ylabel("pitch rate max / limit")
    a3.set_xlabel("DLC")
    return save_figure(fig, path)


def plot_lidar_evaluation(summary: dict[str, Any], curves: dict[str, Any], tip_radius: float,
                          folder: str | Path) -> list[str]:
    """The LIDAR-rotor coherence and the scan pattern of one revolution, as
    ``lidar_coherence.png`` and ``lidar_scan.png`` in ``folder``.

    Parameters
    ----------
    summary, curves : dict
        What :func:`mpc_wt.assessment.lidar.lidar_evaluation` returns.
    tip_radius : float
        Rotor tip radius [m].
    folder : str or Path
        Where the plots go (made if missing).

    Returns
    -------
    list of str
        The files written.
    """
    d = Path(folder)
    d.mkdir(parents=True, exist_ok=True)
    plot_lidar_coherence(curves["frequency_hz"], curves["coherence"],
                         summary["coherence_bandwidth_Hz"], summary["mean_speed_mps"],
                         d / "lidar_coherence.png")
    plot_scan_pattern(curves["beam_azimuth_rad"], curves["blade_azimuth_rad"],
                      curves["lidar_radius"], tip_radius, d / "lidar_scan.png")
    return [str(d / "lidar_coherence.png"), str(d / "lidar_scan.png")]



def plot_psd_grid(panels: Sequence[tuple[str, str, Sequence[tuple[str, np.ndarray, np.ndarray]]]],
                  path: str | Path, rotor_hz: float | None = None,
                  title: str = "") -> Path:
    """Spectra of several channels, one panel each, several runs overlaid.

    Parameters
    ----------
    panels : sequence of (str, str, sequence of (str, ndarray, ndarray))
        Per panel: the channel's name, its PSD unit (e.g. ``"(kN m)^2/Hz"``), and per run a
        label, frequencies [Hz] and PSD.
    path : str or Path
        The PNG file.
    rotor_hz : float, optional
        Rotor frequency 1P [Hz]: 1P, 3P and 6P are marked.
    title : str
        Figure title.

    Returns
    -------
    Path
        The PNG file.
    """
    plt = pyplot()
    n = max(len(panels), 1)
    cols = 2 if n > 1 else 1
    rows = math.ceil(n / cols)
    fig, axs = plt.subplots(rows, cols, figsize=(6.0 * cols, 3.0 * rows), dpi=110,
                            squeeze=False)
    for ax, (name, unit, runs) in zip(axs.flat, panels):
        for label, f, p in runs:
            keep = (f > 0) & (f <= 10.0)
            ax.loglog(f[keep], np.maximum(p[keep], 1e-30), lw=0.9, label=label)
        if rotor_hz:
            for k in (1, 3, 6):
                ax.axvline(k * rotor_hz, color="0.6", ls=":", lw=0.7)
        ax.set_title(name, fontsize=9)
        ax.set_xlabel("frequency [Hz]", fontsize=8)
        ax.set_ylabel(f"PSD [{unit}]", fontsize=8)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    for ax in list(axs.flat)[len(panels):]:
        ax.set_visible(False)
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path)


#: the channels :func:`plot_verify` draws: name, axis label, scale (SI value / scale)
_VERIFY_PANELS = (("gen_power", "generator power [MW]", 1e6),
                  ("rotor_speed", "rotor speed [rpm]", math.pi / 30),
                  ("pitch_1", "blade 1 pitch [deg]", math.pi / 180),
                  ("gen_torque", "generator torque [kN m]", 1e3),
                  ("flap_moment_1", "blade 1 out-of-plane root moment [MN m]", 1e6),
                  ("tower_base_fa_moment", "tower base fore-aft moment [MN m]", 1e6))


def plot_verify(t_ref: np.ndarray, ref: Mapping[str, np.ndarray], t: np.ndarray,
                ours: Mapping[str, np.ndarray], path: str | Path, title: str = "") -> Path:
    """OpenFAST's run and mpc-wt's of the same case, side by side in time: power, rotor
    speed, pitch, torque, blade root and tower base moments (those both runs have).

    Parameters
    ----------
    t_ref, t : ndarray
        The runs' times [s] (OpenFAST's, mpc-wt's).
    ref, ours : mapping of str to ndarray
        Their channels by mpc-wt's names (SI).
    path, title
        The PNG file to write and the figure's title, as :func:`plot_psd_grid` takes them.

    Returns
    -------
    Path
        ``path``, written.
    """
    plt = pyplot()
    panels = [p for p in _VERIFY_PANELS if p[0] in ref and p[0] in ours]
    rows = max(math.ceil(len(panels) / 2), 1)
    fig, axs = plt.subplots(rows, 2, figsize=(12.0, 2.6 * rows), dpi=110, squeeze=False,
                            sharex=True)
    for ax, (name, label, scale) in zip(axs.flat, panels):
        ax.plot(t_ref, np.asarray(ref[name]) / scale, lw=0.8, label="OpenFAST")
        ax.plot(t, np.asarray(ours[name]) / scale, lw=0.8, label="mpc-wt", alpha=0.85)
        ax.set_ylabel(label, fontsize=8)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    for ax in axs[-1]:
        ax.set_xlabel("time [s]", fontsize=8)
    for ax in list(axs.flat)[len(panels):]:
        ax.set_visible(False)
    if title:
        fig.suptitle(title, fontsize=10)
    return save_figure(fig, path)
