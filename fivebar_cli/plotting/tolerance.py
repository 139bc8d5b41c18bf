"""Figures of the tolerance study: robust and possible bands over the nominal spaces, and the robust
area of every aspect against the tolerance."""

from __future__ import annotations

from fivebar_cli.plotting import pyplot
from fivebar_cli.plotting.trees import draw_layers


def figure_bands(study):
    """Per space: the possible region (root minus impossible) at the largest tolerance in grey, then
    the robust region of each tolerance on top of the previous one (the nominal region first): each
    ring of colour is what that tolerance loses to the next."""
    plt = pyplot()
    from matplotlib.patches import Patch

    tolerances = sorted({t for t, _ in study.pavings})
    colours = [(0.1, 0.1, 0.1)] + [plt.get_cmap("plasma")(0.15 + 0.7 * k / max(len(tolerances) - 2, 1))[:3]
                                   for k in range(len(tolerances) - 1)]
    fig, axes = plt.subplots(1, 2, figsize=(12, 6.6), dpi=120)
    for ax, space in zip(axes, ("workspace", "jointspace")):
        largest = study.pavings[tolerances[-1], space]
        layers = [(largest.outside.complement(), (0.88, 0.88, 0.88))]
        layers += [(study.pavings[tol, space].inside, c) for tol, c in zip(tolerances, colours)]
        draw_layers(ax, layers, study.mechanism.spaces()[space].axes, outline=[],
                    marks=study.mechanism.marks(space))
        ax.set_title(f"{space}: robust region per tolerance", fontsize=10)
    handles = [Patch(facecolor=(0.88, 0.88, 0.88), label=f"possible at T = {tolerances[-1]:g}")]
    handles += [Patch(facecolor=c, label="nominal" if tol == 0 else f"robust at T = {tol:g}")
                for tol, c in zip(tolerances, colours)]
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8, frameon=False)
    fig.suptitle(f"{study.mechanism.name}: manufacturing tolerances on every link length, depth {study.depth}")
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    return fig


def figure_aspect_areas(study):
    """Robust workspace area of each nominal aspect against the tolerance (relative to nominal)."""
    plt = pyplot()
    tolerances = sorted(study.fates)
    fig, ax = plt.subplots(figsize=(7.5, 5), dpi=120)
    for a in study.nominal.aspects:
        ratios = []
        for tol in tolerances:
            fate = next(f for f in study.fates[tol] if f.number == a.number)
            ratios.append(fate.robust_area / fate.nominal_area if fate.nominal_area else 0.0)
        ax.plot(tolerances, ratios, "o-", label=f"aspect {a.number}")
    ax.set_xlabel("tolerance T on every link length")
    ax.set_ylabel("robust workspace area / nominal")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    if study.nominal.aspects:  # (none found at a small depth: no legend, not matplotlib's warning)
        ax.legend(fontsize=7, ncol=2)
    ax.set_title(f"{study.mechanism.name}: aspects under tolerances (depth {study.depth})", fontsize=10)
    fig.tight_layout()
    return fig
