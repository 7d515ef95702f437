"""The estimate against evaluations (EXPERIMENTS.md, "How rare is a failure"): the
checkpoints of estimate summaries (`summary.json`'s `checkpoints`, the estimates the
stopping rule saw after each block), one line with its 95% band per summary, for
P(fails) and P(fails | fair), beside a reference value and its interval.

    python3 scripts/estimate_figure.py --out figure.png \\
        --reference 0.1593,0.1523,0.1666 --reference-fair 0.0092,0.0067,0.0127 \\
        mc=out/est-mc/summary.json is=out/est-is/summary.json

Needs matplotlib. Writes a PNG (matplotlib's SVG sizes itself in points, which the
committed figures' test does not read)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path


def _band(text: str | None) -> tuple[float, float, float] | None:
    if text is None:
        return None
    p, low, high = (float(x) for x in text.split(","))
    return p, low, high


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", help="LABEL=summary.json")
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--reference", help="P(fails) of the reference: p,low,high")
    ap.add_argument("--reference-fair", help="P(fails | fair) of the reference: p,low,high")
    ap.add_argument("--log", action="store_true",
                    help="both axes on log scales (runs of unequal budgets, a rare target; "
                         "estimates of 0 are left out)")
    args = ap.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    panels = [("p_fail", "P(fails)", _band(args.reference)),
              ("p_fail_given_fair", "P(fails | fair)", _band(args.reference_fair))]
    for ax, (key, title, ref) in zip(axes, panels, strict=True):
        for run in args.runs:
            label, path = run.split("=", 1)
            points = json.loads(Path(path).read_text())["checkpoints"]
            # On log scales an estimate of 0 has no place: it is left out.
            shown = [c for c in points if c[key]["p"] is not None and (c[key]["p"] > 0 or not args.log)]
            refused = [c["evaluations"] for c in points if c[key]["p"] is None]
            floor = ref[0] / 8 if args.log and ref is not None else 0.0
            x = [c["evaluations"] for c in shown]
            line = ax.plot(x, [c[key]["p"] for c in shown], marker=".", label=label)[0]
            ax.fill_between(x, [c[key]["ci95_low"] for c in shown], [c[key]["ci95_high"] for c in shown],
                            color=line.get_color(), alpha=0.2)
            if refused:
                ax.plot(refused, [floor] * len(refused), "x", color=line.get_color(),
                        label=f"{label}: refused (too few effective failures or degenerate weights)")
        if ref is not None:
            ax.axhline(ref[0], color="black", lw=1, label="reference (Monte Carlo, its 95% interval grey)")
            ax.axhspan(ref[1], ref[2], color="black", alpha=0.1)
        ax.set_title(title)
        ax.set_xlabel("evaluations (draws of the space)")
        if args.log:
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
            if ref is not None:
                ax.set_ylim(ref[0] / 10, ref[0] * 30)
        ax.set_ylabel("estimate, 95% interval")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)


if __name__ == "__main__":
    main()
