"""Make the README's headline image, bifurcation_hb1.png: figure 5 of ``rockjit paper`` at
h/b = 1, drawn by the same function from the same sweeps.

Run from the repository's root (about 10 s with numba's cache warm):

    python docs/_static/make_headline.py

The sweeps are the paper's (:func:`rockjit.study.paper.plan_paper`: both laws at h/b = 1,
omega = 1.3, the study's amplitude step and periods), and the figure is
:func:`rockjit.study.paper.draw_fig5`, the one ``rockjit paper`` writes as
``fig5_bifurcation_hb1.png``, saved in the paper's default style.
"""

from __future__ import annotations

import argparse
from pathlib import Path

HERE = Path(__file__).resolve().parent
HEADLINE = HERE / "bifurcation_hb1.png"


def make(path=HEADLINE, *, periods=None, alpha_step=None):
    """Compute the paper's h/b = 1 sweeps and write figure 5 of them to ``path``; returns the
    path. ``periods`` and ``alpha_step`` (default the study's) make a quick, coarse image."""
    import matplotlib
    matplotlib.use("Agg")

    from rockjit.grids.plan import run
    from rockjit.plotting import style
    from rockjit.storage.atomic import save_figure
    from rockjit.study import paper

    kw = {k: v for k, v in dict(periods=periods, alpha_step=alpha_step).items()
          if v is not None}
    plan = paper.plan_paper(**kw)
    sweeps = {law: run(plan.sweeps[(1, law)]) for law in ("housner", "mao")}
    path = Path(path)
    with style.use("default") as st:
        fig = paper.draw_fig5(sweeps, 1)
        save_figure(fig, path, dpi=st.rc["savefig.dpi"])
    return path


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(HEADLINE), help="where to write the image")
    args = ap.parse_args(argv)
    print(make(args.out))


if __name__ == "__main__":
    main()
