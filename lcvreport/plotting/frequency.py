"""Eigenvalue maps, root loci, damping over speed and frequency responses."""
from __future__ import annotations


import numpy as np
from matplotlib.figure import Figure

from .style import PAGE_WIDTH_IN, PALETTE, SMALL_PT, new_figure


# ------------------------------------------------------------------ eigenvalues
def fig_eigenvalues(sets: list[tuple[str, np.ndarray]], title: str, upper: bool = False,
                    connect_mode: int | None = None) -> Figure:
    """Eigenvalue map(s): real part [1/s] against imaginary part [1/s].

    ``upper`` shows only the upper-left quadrant; ``connect_mode`` (1-based, mode
    order of :func:`lcvreport.analysis.modes.mode_order`) joins that mode across the
    sets with a dashed black line, as the thesis does for Mode 7.
    """
    fig, ax = new_figure(PAGE_WIDTH_IN, 3.6)
    markers = "osD^v<>ph"
    for i, (label, lam) in enumerate(sets):
        ax.scatter(lam.real, lam.imag, s=18, marker=markers[i % len(markers)], color=PALETTE[i % len(PALETTE)],
                   label=label, zorder=3)
    if connect_mode is not None:
        pts = np.array([lam[connect_mode - 1] for _, lam in sets])
        ax.plot(pts.real, pts.imag, "k--", lw=1, label=f"Mode {connect_mode}")
    ax.axvline(0, color="black", lw=0.8)
    ax.axhline(0, color="black", lw=0.5)
    if upper:
        ax.set_xlim(right=0)
        ax.set_ylim(bottom=0)
    ax.set_xlabel("Re(lambda) [1/s]")
    ax.set_ylabel("Im(lambda) [1/s]")
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=SMALL_PT)
    ax.set_title(title, fontsize=9)
    return fig


def fig_root_locus(speeds_kph: np.ndarray, eigenvalues: np.ndarray, title: str,
                   critical_kph: float | None = None) -> Figure:
    """Root locus over speed: every eigenvalue [1/s] coloured by the speed [km/h]."""
    fig, ax = new_figure(PAGE_WIDTH_IN, 3.8)
    sc = None
    for j in range(eigenvalues.shape[1]):
        sc = ax.scatter(eigenvalues[:, j].real, eigenvalues[:, j].imag, c=speeds_kph, cmap="viridis", s=6,
                        zorder=3, label="_nolegend_" if j else "eigenvalues")
    cb = fig.colorbar(sc, ax=ax)
    cb.set_label("speed [km/h]", fontsize=8)
    cb.ax.tick_params(labelsize=SMALL_PT)
    ax.axvline(0, color="black", lw=0.8)
    ax.axhline(0, color="black", lw=0.5)
    # zoom to the oscillatory modes: far-left real poles (fast, well damped) would squeeze them
    osc = np.abs(eigenvalues.imag) > 1e-9 * np.abs(eigenvalues).max()
    if osc.any():
        left = 1.15 * min(eigenvalues.real[osc].min(), 0.0) - 0.05
        right = max(0.1 * abs(left), 1.15 * eigenvalues.real.max())
        hidden = int(np.sum(eigenvalues.real.min(axis=0) < left))
        ax.set_xlim(left, right)
        top = 1.1 * np.abs(eigenvalues.imag[osc]).max()
        ax.set_ylim(-top, top)
        if hidden:
            ax.text(0.01, 0.02, f"{hidden} real mode(s) left of the frame (faster, Re < {left:.3g} 1/s; in the CSV)",
                    transform=ax.transAxes, fontsize=SMALL_PT, ha="left", va="bottom")
    note = "stable throughout" if critical_kph is None else f"critical speed {critical_kph:.1f} km/h"
    ax.set_xlabel("Re(lambda) [1/s]")
    ax.set_ylabel("Im(lambda) [1/s]")
    ax.grid(True, lw=0.3)
    ax.set_title(f"{title} ({note})", fontsize=9)
    return fig


def fig_damping_over_speed(speeds_kph: np.ndarray, zeta: np.ndarray, max_real: np.ndarray, title: str,
                           critical_kph: float | None, speed_kph: float | None = None) -> Figure:
    """Least damping ratio [-] and largest real part [1/s] against speed [km/h]."""
    fig, (a1, a2) = new_figure(PAGE_WIDTH_IN, 3.8, nrows=2, sharex=True)
    a1.plot(speeds_kph, zeta, color=PALETTE[0])
    a1.set_ylabel("least damping ratio [-]")
    a2.plot(speeds_kph, max_real, color=PALETTE[1])
    a2.axhline(0, color="black", lw=0.8)
    a2.set_ylabel("max Re(lambda) [1/s]")
    a2.set_xlabel("speed [km/h]")
    for ax in (a1, a2):
        ax.grid(True, lw=0.3)
        if critical_kph is not None:
            ax.axvline(critical_kph, color="red", ls="--", lw=1)
        if speed_kph is not None:
            ax.axvline(speed_kph, color="black", ls=":", lw=1)
    note = "stable throughout" if critical_kph is None else f"critical speed {critical_kph:.1f} km/h (red)"
    a1.set_title(f"{title}: {note}" + ("; dotted: the report's speed" if speed_kph is not None else ""), fontsize=9)
    return fig


def fig_frequency(f_hz: np.ndarray, curves: list[tuple[str, np.ndarray]], ylabel: str, title: str,
                  mark_hz: float | None = None, logy: bool = False, peak: tuple | None = None) -> Figure:
    """Curves against frequency [Hz] (RA(f), gains)."""
    fig, ax = new_figure(PAGE_WIDTH_IN, 3.2)
    for i, (label, y) in enumerate(curves):
        ax.plot(f_hz, y, color=PALETTE[i % len(PALETTE)], lw=1.1, label=label)
    if mark_hz is not None:
        ax.axvline(mark_hz, color="black", ls=":", lw=1)
    if peak is not None:
        ax.plot([peak[0]], [peak[1]], "o", color="black", ms=4)
        ax.annotate(f"peak {peak[1]:.3f} at {peak[0]:.3f} Hz", peak, xytext=(10, 4), textcoords="offset points",
                    fontsize=SMALL_PT)
    if logy:
        ax.set_yscale("log")
    ax.set_xlabel("steer frequency [Hz]")
    ax.set_ylabel(ylabel)
    ax.grid(True, lw=0.3, which="both")
    ax.legend(fontsize=SMALL_PT, ncol=2)
    ax.set_title(title, fontsize=9)
    return fig
