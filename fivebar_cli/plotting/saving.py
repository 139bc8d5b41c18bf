"""Figures saved as files: drawn, made safe for names from the user's files, written atomically,
freed (the commands' figures, and `save(..., figures=True)` of the library's results)."""

from __future__ import annotations

from pathlib import Path

from fivebar_cli.io.files import save_figure
from fivebar_cli.plotting import pyplot


def draw_and_save(make, path: Path) -> Path:
    """Draw a figure with `make()`, save it atomically as PNG, free it. Names from the user's files
    (in titles and legends) are drawn as written (`literal_texts`); a name whose `$...$` is not even
    valid mathtext makes the figure be drawn again with every text literal but the axis labels.
    On the backend in use (the CLI selects Agg)."""
    import matplotlib

    before = set(pyplot().get_fignums())
    try:
        return _save(make(), path)
    except ValueError as exc:  # matplotlib's mathtext parser, on a `$` of a name
        if "Parse" not in type(exc).__name__ + str(exc):
            raise
        for number in set(pyplot().get_fignums()) - before:
            pyplot().close(number)  # the figure that failed to draw

    with matplotlib.rc_context({"text.parse_math": False}):
        fig = make()
    for ax in fig.axes:
        for label in (ax.xaxis.label, ax.yaxis.label):
            label.set_parse_math(True)  # the axis labels are ours (theta_1, rho_1, ...)
    return _save(fig, path)


def _save(fig, path: Path) -> Path:
    try:
        literal_texts(fig)
        settled_layout(fig)
        return save_figure(fig, path)
    finally:
        pyplot().close(fig)


def settled_layout(fig) -> None:
    """Forget a layout that `tight_layout()` already applied. It leaves a placeholder engine that
    does nothing on a draw, but whose mere presence makes `savefig` draw the whole figure once
    more before the real draw (images resampled, texts laid out: a third of a figure's cost). The
    positions are already set, so the PNG is the same without it."""
    from matplotlib.layout_engine import PlaceHolderLayoutEngine

    if isinstance(fig.get_layout_engine(), PlaceHolderLayoutEngine):
        fig.set_layout_engine(None)


def literal_texts(fig) -> None:
    """Titles, legends and notes are drawn as written, not as mathtext: they hold names from the
    user's files, where `$` is a character (`$\\foo$` would otherwise fail to draw). Axis labels
    and tick labels keep their mathtext (theta_1, 10^2)."""
    texts = [fig._suptitle, *fig.texts]
    for legend in [*fig.legends, *(ax.get_legend() for ax in fig.axes)]:
        if legend is not None:
            texts += [*legend.get_texts(), legend.get_title()]
    for ax in fig.axes:
        texts += [ax.title, ax._left_title, ax._right_title, *ax.texts]
    for text in texts:
        if text is not None:
            text.set_parse_math(False)
