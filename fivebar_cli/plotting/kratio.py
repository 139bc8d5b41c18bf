"""The paper's Table 1 as a figure: K against depth, ours, the paper's procedure and the print."""

from __future__ import annotations

from fivebar_cli.plotting import pyplot


def figure_kratio(rows: list[dict]):
    """K = n / 4^d against depth: our tests, the paper's procedure and the paper's printed values."""
    plt = pyplot()
    spaces = list(dict.fromkeys(r["space"] for r in rows))
    fig, axes = plt.subplots(1, len(spaces), figsize=(5 * len(spaces), 4.2), dpi=150, sharey=True, squeeze=False)
    axes = axes[0]
    for ax, space in zip(axes, spaces):
        for mech in sorted({r["mechanism"] for r in rows}):
            sel = [r for r in rows if r["space"] == space and r["mechanism"] == mech]
            if not sel:
                continue
            d = [r["depth"] for r in sel]
            line, = ax.semilogy(d, [r["K"] for r in sel], "o-", label=f"{mech}: tight tests")
            if sel[0]["paper_procedure_K"] != "":
                ax.semilogy(d, [r["paper_procedure_K"] for r in sel], "s--", color=line.get_color(),
                            alpha=0.7, label=f"{mech}: paper's procedure")
            printed = [(r["depth"], r["paper_printed_percent"] / 100) for r in sel if r["paper_printed_percent"] != ""]
            if printed:
                ax.semilogy(*zip(*printed), "x", color="k", markersize=7)
        ax.set_title({"jointspace": "Joint space", "workspace": "Workspace"}.get(space, space))
        ax.set_xlabel("depth d")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    axes[0].set_ylabel(r"$K = n / 2^{\mathrm{dim}\cdot d}$  (x: paper's Table 1)")
    fig.tight_layout()
    return fig
