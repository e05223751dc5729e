"""The README's promises: its Python examples run as written (in a fresh process, from the
repository) and print what they compute, its first two commands are the two set-up commands,
it stays a screen or two, and every number it quotes from rockjit's results is what rockjit
computes today (each recomputed here, at the README's settings, and compared with the text)."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text(encoding="utf-8")


def _blocks(lang):
    return re.findall(rf"```{lang}\n(.*?)```", README, flags=re.S)


def test_the_python_examples_run_as_written(tmp_path):
    blocks = _blocks("python")
    assert blocks, "the README has no Python example"
    code = "\n".join(blocks)
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                          text=True, env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin",
                                          "MPLBACKEND": "Agg", "HOME": str(tmp_path)})
    assert proc.returncode == 0, proc.stderr[-3000:]
    # run as a script, the quickstart shows every result it makes, each in a few lines
    printed = proc.stdout.splitlines()
    assert len(re.findall(r"^print\(", code, flags=re.M)) >= 6
    assert "('symmetric', 1)" in proc.stdout and "<rockjit.SweepResult: 501 amplitudes>" in printed
    assert any(ln.startswith("<rockjit.BasinResult: 100×100") for ln in printed)
    assert any(ln.startswith("<rockjit.ErosionResult: 36 amplitudes") for ln in printed)
    assert "'overturn'" in printed[-1]
    assert len(printed) <= 60, proc.stdout


def test_the_examples_comments_state_what_the_code_returns():
    # the quickstart's claims, checked against the library
    import rockjit
    from rockjit import Block, Harmonic
    res = rockjit.simulate(Block(hb=1, law="housner"), Harmonic(alpha=0.6, omega=1.3),
                           lyapunov=True)
    assert rockjit.classify_result(res) == ("symmetric", 1)
    assert "('symmetric', 1)" in README
    assert abs(res.lyapunov[0] + 0.57) < 0.01 and abs(res.lyapunov[1] + 0.57) < 0.01
    quoted = re.search(r"`Block\(hb=0.5\)` says\s+`([^`]+)`", README).group(1)
    try:
        Block(hb=0.5)
    except ValueError as exc:
        assert str(exc).startswith(" ".join(quoted.split())), (str(exc), quoted)
    else:
        raise AssertionError("Block(hb=0.5) was accepted")


def test_it_opens_with_the_two_set_up_commands():
    first = _blocks("bash")[0].strip().splitlines()
    assert first[0].startswith('pip install -e . && rockjit paper --out paper')
    assert first[1].startswith('pip install -e ".[test]" && python -m pytest')
    assert README.index("```bash") < README.index("## ")


def test_it_stays_short_and_points_inside_the_repository():
    assert len(README.splitlines()) <= 150
    for target in re.findall(r"\]\(([^)#]+)\)", README):
        if not target.startswith("http"):
            assert (ROOT / target).exists(), target


def test_one_version_everywhere():
    # pyproject reads the version from rockjit/__init__.py; the citation metadata and the
    # installed package's metadata say the same
    import importlib.metadata

    import pytest

    import rockjit
    tomllib = pytest.importorskip("tomllib" if sys.version_info >= (3, 11) else "tomli")
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert "version" not in project["project"] and "version" in project["project"]["dynamic"]
    assert project["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "rockjit.__version__"}
    cff = re.search(r"^version:\s*(\S+)\s*$", (ROOT / "CITATION.cff").read_text(), re.M)
    assert cff and cff.group(1).strip("\"'") == rockjit.__version__
    assert importlib.metadata.version("rockjit") == rockjit.__version__


#: The pages that quote the same results as the README, in the same words.
CLAIMS = {"README.md": README, **{name: (ROOT / "docs" / name).read_text(encoding="utf-8")
                                  for name in ("study.md", "theory/study.md")}}


def _number(pattern, text=README):
    m = re.search(pattern, " ".join(text.split()))
    assert m, pattern
    return m


def _every(pattern, names=tuple(CLAIMS)):
    """Each page's quote of a result: ``{page: match}``; every page in ``names`` quotes it."""
    return {name: _number(pattern, CLAIMS[name]) for name in names}


def test_the_multiperiodic_examples_fate_is_todays():
    import rockjit
    from rockjit import Block, Harmonic
    quotes = _every(r"of (\d+) runs within \$10\^\{-10\}\$ of its initial state, (\d+) % "
                    r"overturn and (\d+) % settle on a period-(\d+) orbit")
    assert len({m.groups() for m in quotes.values()}) == 1, quotes
    n, over, other, period = (int(v) for v in quotes["README.md"].groups())
    f = rockjit.fate(Block(hb=1), Harmonic(alpha=0.969, omega=1.3), ensemble=n)
    assert f.settings["spread"][1] == 1e-10
    assert round(100 * f.probabilities["overturn"]) == over
    assert round(100 * f.probabilities[f"multiperiodic p={period}"]) == other
    # its transient's exponent and horizons (the theory page quotes them)
    lam, t_round, t_pert = _number(r"exponent is \$\\lambda_1 \\approx ([\d.]+)\$\. Rounding .*? by "
                                   r"\$t\^\* \\approx (\d+)\$, and a perturbation of \$10\^\{-10\}\$ by "
                                   r"\$t\^\* \\approx (\d+)\$", CLAIMS["theory/study.md"]).groups()
    assert f"{f.lambda1:.2f}" == lam
    assert (round(f.horizon_rounding), round(f.horizon)) == (int(t_round), int(t_pert))
    # with the study's embedded forcing (the docs quote it)
    emb = _every(r"embedded forcing[^.]*?(\d+) % overturn and (\d+) % period 7",
                 ("study.md", "theory/study.md"))
    assert len({m.groups() for m in emb.values()}) == 1, emb
    e = rockjit.fate(Block(hb=1), Harmonic(alpha=0.969, omega=1.3, embedded=True), ensemble=n)
    assert (round(100 * e.probabilities["overturn"]),
            round(100 * e.probabilities["multiperiodic p=7"])) == \
        tuple(int(v) for v in emb["study.md"].groups())
    assert "64 runs within 1e-10 of z0" in README  # the quickstart's call: the default ensemble
    assert f.settings["ensemble"] == rockjit.fate.plan(
        Block(hb=1), Harmonic(alpha=0.969, omega=1.3)).ensemble


def test_the_integrity_of_both_laws_is_as_quoted():
    import numpy as np

    import rockjit
    from rockjit import Block, Harmonic
    quotes = _every(r"global integrity \(GIM\) is ([\d.]+) of Housner's at \$\\alpha = ([\d.]+)\$ "
                    r"and ([\d.]+) of it at \$\\alpha = ([\d.]+)\$, while its integrity factor "
                    r"\(IF\) stays within ([\d.]+) of Housner's up to \$\\alpha = ([\d.]+)\$ and "
                    r"falls to ([\d.]+)–([\d.]+) of it from \$\\alpha = ([\d.]+)\$ to \$([\d.]+)\$ "
                    r"\((\d+) × \d+ basins, (\d+) periods\)")
    assert len({m.groups() for m in quotes.values()}) == 1, quotes
    r_lo, a_lo, r_hi, a_hi, tol, a_same, if_lo, if_hi, a_half, a_end, grid, periods = \
        quotes["README.md"].groups()
    step = 0.1
    alphas = np.round(np.arange(float(a_lo), float(a_end) + step / 2, step), 10)
    assert float(a_hi) in alphas and float(a_same) in alphas and float(a_half) in alphas
    prof = {law: rockjit.erosion(Block(hb=1, law=law), Harmonic(omega=1.3), alphas, int(grid),
                                 integration=rockjit.Integration(periods=int(periods)))
            for law in ("housner", "mao")}
    gim = prof["mao"].GIM / prof["housner"].GIM
    assert f"{gim[alphas == float(a_lo)][0]:.2f}" == r_lo
    assert f"{gim[alphas == float(a_hi)][0]:.2f}" == r_hi
    same = alphas <= float(a_same) + 1e-9
    assert np.all(np.abs(prof["mao"].IF - prof["housner"].IF)[same] <= float(tol))
    late = alphas >= float(a_half) - 1e-9
    ratio = prof["mao"].IF[late] / prof["housner"].IF[late]
    assert (f"{ratio.min():.2f}", f"{ratio.max():.2f}") == (if_lo, if_hi)
    # the study page quotes each law's GIM at both ends
    ends = _number(r"GIM falls from ([\d.]+) to ([\d.]+) over \$\\alpha = 0.3\$–\$0.9\$ under "
                   r"Housner's law and from ([\d.]+) to ([\d.]+) under Mao's", CLAIMS["study.md"])
    got = [f"{prof[law].GIM[alphas == a][0]:.2f}" for law in ("housner", "mao")
           for a in (0.3, 0.9)]
    assert got == list(ends.groups())


@pytest.mark.slow
def test_the_mean_integrity_at_the_studys_resolution_is_as_quoted():
    import rockjit
    from rockjit import Block, Harmonic
    pages = {"study.md": r"\(mean (\d\.\d+) against (\d\.\d+)\)",
             "theory/study.md": r"the mean GIM over \$\\alpha = 0.3\$–\$0.9\$ is (\d\.\d+) "
                                r"against Housner's (\d\.\d+)",
             "guide/erosion.md": r"the mean GIM over \$\\alpha \\in \[0.3, 0.9\]\$ is (\d\.\d+) "
                                 r"under Housner's law and (\d\.\d+) under Mao's"}
    mean = {law: rockjit.erosion(Block(hb=1, law=law), Harmonic(omega=1.3),
                                 rockjit.alpha_grid((0.3, 0.9), 0.01), 100).GIM.mean()
            for law in ("housner", "mao")}
    for page, pattern in pages.items():
        text = (ROOT / "docs" / page).read_text(encoding="utf-8")
        a, b = _number(pattern, text).groups()
        order = ("mao", "housner") if page == "theory/study.md" else ("housner", "mao")
        assert (a, b) == tuple(f"{mean[law]:.2f}" for law in order), page
    # and the reference that index.html puts beside a paper's own profiles
    from rockjit.study.report import GIM_PUBLISHED
    assert {law: f"{v:.2f}" for law, v in GIM_PUBLISHED.items()} == \
        {law: f"{v:.2f}" for law, v in mean.items()}


def test_maos_overturning_onset_is_as_quoted():
    import numpy as np

    import rockjit
    from rockjit import Block, Harmonic
    pages = [README] + [(ROOT / "docs" / n).read_text(encoding="utf-8")
                        for n in ("index.md", "theory/study.md")]
    quoted = {_number(r"overturns at every amplitude from α = ([\d.]+)", p).group(1)
              for p in pages}
    assert len(quoted) == 1, quoted
    onset = float(quoted.pop())
    sw = rockjit.sweep(Block(hb=1, law="mao"), Harmonic(omega=1.3),
                       rockjit.alpha_grid((0.5, 1.0), 0.001))
    over = sw.names[sw.label] == "overturn"
    first = np.flatnonzero(~over)[-1] + 1  # every amplitude from here on overturns
    assert round(float(sw.alpha[first]), 3) == onset


# ---- the speed table: each figure as the committed benchmark results state it -------------

RESULTS = ROOT / "benchmarks" / "results"


def _row(what):
    """The README speed table's cell beside ``what``."""
    for line in README.splitlines():
        if line.startswith(f"| {what} |"):
            return line.split("|")[2]
    raise AssertionError(f"no row {what!r} in the README's speed table")


def _results(name, pattern):
    m = re.search(pattern, (RESULTS / name).read_text(encoding="utf-8"))
    assert m, (name, pattern)
    return m


def _decade(v):
    import math
    return math.floor(math.log10(float(v)) + 1e-9)


def test_the_reference_run_figures_are_the_benchmarks():
    cell = _row("the study's reference run, 500 periods")
    ms, err, speed, bdf = re.search(r"about (\d+) ms at an error of (\S+): some \*\*(\d+)x\*\* "
                                    r"faster .* whose error is (\S+)", cell).groups()
    row = _results("reference_run.md", r"\| rockjit \| N=160 \(default\) \| closed \| (\S+) \|"
                                       r"(?:[^|]*\|){2} (\S+) \|")
    assert round(float(row.group(1)) * 1000) == int(ms)
    assert _decade(row.group(2)) == _decade(err)
    got = float(_results("reference_run.md", r"rockjit is \*\*(\d+)x\*\* faster").group(1))
    assert int(speed) <= got < 1.1 * int(speed)  # "some 2000x": the measured 2097x, rounded down
    bdf_err = _results("reference_run.md",
                       r"\| scipy BDF \(the study's\) \|(?:[^|]*\|){5} (\S+) \|")
    assert _decade(bdf_err.group(1)) == _decade(bdf)


def test_the_grid_figures_are_the_benchmarks():
    basin = re.search(r"\*\*([\d.]+) s\*\*", _row("the study's 100 × 100 basin, 500 periods"))
    sweep = re.search(r"\*\*([\d.]+) s\*\*", _row("its 501-amplitude sweep with λmax"))
    reached = re.findall(r"\*\*reached\*\* \(([\d.]+) s\)", (RESULTS / "grids.md").read_text())
    assert [basin.group(1), sweep.group(1)] == reached[:2]


def test_the_paper_figures_are_the_benchmarks():
    warm, cold = re.search(r"\*\*(\d+) s\*\* once the kernels are cached \((\d+) s cold\)",
                           _row("`rockjit paper`, every figure and table")).groups()
    got = _results("paper.md", r"\*\*end to end\*\*[^|]*\| ([\d.]+) \| ([\d.]+) \|")
    assert (round(float(got.group(1))), round(float(got.group(2)))) == (int(cold), int(warm))


def test_the_peers_basin_figures_are_the_benchmarks():
    lo, hi = re.search(r"about (\d+)x to (\d+)x on the basin",
                       _row("the same block in numbakit-ode, diffrax, SUNDIALS CVODE")).groups()
    text = (RESULTS / "peers.md").read_text()
    table = text[text.index("At equal label accuracy"):]
    ratios = [float(v) for v in re.findall(r"^\| (?:nbkode|diffrax|cvode) \|.*\| (\S+) \|$",
                                           table, re.M)]
    assert ratios and (int(lo), int(hi)) == (int(min(ratios) // 100 * 100),
                                             int(max(ratios) // 100 * 100))


def test_the_ground_figures_are_the_benchmarks():
    rows = {"a 200 × 200 overturning spectrum of a one-sine pulse, every boundary located":
            r"\| spectrum: 200 x 200 one-sine[^|]*\| [^|]* \| ([\d.]+) \|(?:[^|]*\|){4} ([\d.]+) \|",
            "fragility over the FEMA P695 far-field set, 50 intensities, both laws":
            r"\| IDA: 44 records x 50 intensities x 2 laws[^|]*\| [^|]* \| ([\d.]+) \|"
            r"(?:[^|]*\|){4} ([\d.]+) \|"}
    for what, pattern in rows.items():
        fast, slow = re.search(r"\*\*(\d+) s\*\* \(the scipy path: about (\d+) min\)",
                               _row(what)).groups()
        got = _results("ground.md", pattern)
        assert round(float(got.group(1))) == int(fast), what
        assert round(float(got.group(2)) / 60) == int(slow), what


def test_the_peers_single_run_figures_are_the_benchmarks():
    # every peer's cheapest run at each error target over rockjit's, per scene
    lo, hi = re.search(r"rockjit (\d+)x to (\d+)x faster on single runs",
                       _row("the same block in numbakit-ode, diffrax, SUNDIALS CVODE")).groups()
    text = (RESULTS / "peers.md").read_text()
    table = text[text.index("Every method's cheapest run per target"):]
    ratios = []
    for line in re.findall(r"^\| 1e-\d+ \|.*$", table, re.M):
        cells = [c.strip() for c in line.strip("|").split("|")]
        times = [float(c.split()[0]) if re.match(r"[\d.]", c) else None for c in cells[2:8]]
        ratios += [t / times[0] for t in times[1:] if t]  # the five peers, not scipy's
    assert ratios
    assert (int(lo), int(hi)) == (round(min(ratios)), int(float(f"{max(ratios):.2g}")))


def test_the_sites_front_page_quotes_the_readmes_figures():
    # docs/index.md repeats four of the speed table's figures (held to the results above)
    page = " ".join((ROOT / "docs" / "index.md").read_text(encoding="utf-8").split())
    ms, speed, basin, paper = re.search(
        r"takes about (\d+) ms, some (\d+) times faster .* 500 periods about ([\d.]+) s on two "
        r"cores; every figure and table of the study in about (\d+) s", page).groups()
    assert f"about {ms} ms" in _row("the study's reference run, 500 periods")
    assert f"**{speed}x**" in _row("the study's reference run, 500 periods")
    assert f"**{basin} s**" in _row("the study's 100 × 100 basin, 500 periods")
    assert f"**{paper} s**" in _row("`rockjit paper`, every figure and table")


def test_the_earthquake_guide_quotes_the_readmes_ground_figures():
    # docs/guide/earthquakes.md repeats the speed table's two ground rows (held to
    # benchmarks/results/ground.md above)
    page = " ".join((ROOT / "docs" / "guide" / "earthquakes.md").read_text(
        encoding="utf-8").split())
    spectrum, ida, spectrum_min, ida_min = re.search(
        r"A 200 × 200 spectrum with its boundaries located takes about (\d+) s, an incremental "
        r"dynamic analysis of the 44 far-field records at 50 intensities and both laws about "
        r"(\d+) s, on two cores; the scipy path would take about (\d+) min for the one and "
        r"about (\d+) min for the other", page).groups()
    rows = ("a 200 × 200 overturning spectrum of a one-sine pulse, every boundary located",
            "fragility over the FEMA P695 far-field set, 50 intensities, both laws")
    for what, fast, slow in zip(rows, (spectrum, ida), (spectrum_min, ida_min)):
        assert f"**{fast} s** (the scipy path: about {slow} min)" in _row(what), what


def test_the_multiperiodic_examples_accurate_overturning_time_is_as_quoted():
    import rockjit
    from rockjit import Block, Harmonic, Integration
    text = CLAIMS["theory/study.md"]
    t, n1, n2, exp = _number(r"overturns at \$t = ([\d.]+)\$\. rockjit at \$N = (\d+)\$ and "
                             r"\$(\d+)\$ agrees to \$10\^\{-(\d+)\}\$", text).groups()
    ends = [rockjit.simulate(Block(hb=1), Harmonic(alpha=0.969, omega=1.3),
                             integration=Integration(n_steps=int(n))) for n in (n1, n2)]
    assert all(r.status == "overturned" for r in ends)
    assert abs(ends[0].t - ends[1].t) < 10.0 ** -int(exp)
    assert f"{ends[1].t:.{len(t.split('.')[1])}f}" == t
    short = _number(r"overturns at \$t = ([\d.]+)\$; the outcome", CLAIMS["study.md"]).group(1)
    assert f"{ends[1].t:.{len(short.split('.')[1])}f}" == short
    # how long it wanders, in forcing periods T = 2 pi / omega
    import math
    wanders = _every(r"the block wanders for about (\d+) periods", ("study.md", "theory/study.md"))
    for m in wanders.values():
        assert int(m.group(1)) == round(ends[1].t * 1.3 / (2 * math.pi))


def test_the_study_pages_basin_measures_are_todays():
    # "What the attractor view adds": per basin and law, the behaviours' shares, the basin
    # entropies, the uncertainty exponent and the integrity, at 100 x 100 cells, 500 periods
    import rockjit
    from rockjit import Block, Harmonic
    text = CLAIMS["study.md"]
    rows = re.findall(r"^\|\s*(\$h/b = [^|]*?)?\s*\| (Housner|Mao) \| ([^|]*) \| [^|]* \| "
                      r"([\d.]+) / ([\d.]+) \| ([\d.]+) \| ([\d.]+) / ([\d.]+) \|$", text, re.M)
    assert len(rows) == 4, rows
    case, basins = None, {}
    for where, law, shares, sb, sbb, unc, gim, if_ in rows:
        if where:
            case = [float(v) for v in re.findall(r"= ([\d.]+)\$", where)]
        hb, alpha, omega = case
        b = basins[hb, law] = rockjit.basin(Block(hb=hb, law=law.lower()),
                                            Harmonic(alpha=alpha, omega=omega, r0=0.0, s0=1.0),
                                            100)
        fr, m = b.fractions(), b.measures()
        for pct, name in re.findall(r"([\d.]+) % (\w+)", shares):
            assert f"{fr[name]:.1f}" == pct, (case, law, name)
        assert (f"{m['basin_entropy']:.3f}", f"{m['boundary_basin_entropy']:.3f}") == (sb, sbb)
        assert f"{m['uncertainty_exponent']['alpha']:.2f}" == unc, (case, law)
        assert (f"{m['integrity']['GIM']:.3f}", f"{m['integrity']['IF']:.3f}") == (gim, if_)
    # the two laws' agreement on the behaviour and on the attractor, h/b = 1 and 2
    from rockjit.grids.identity import agreement, attractor_agreement
    quoted = _number(r"agree on the behaviour of ([\d.]+) % \(\$h/b = 1\$\) and ([\d.]+) % "
                     r"\(\$h/b = 2\$\) of the cells and on the attractor \(matched by kind\) of "
                     r"([\d.]+) % and ([\d.]+) %", text).groups()
    got = [agreement(basins[hb, "Housner"].label, basins[hb, "Mao"].label) for hb in (1, 2)]
    got += [attractor_agreement(basins[hb, "Housner"], basins[hb, "Mao"])["percent"]
            for hb in (1, 2)]
    assert tuple(f"{v:.1f}" for v in got) == quoted


def test_the_share_plotted_after_the_fall_is_todays():
    # the study's sweeps integrated on past overturning: what they plot after the block fell
    import rockjit
    from rockjit import Block, Harmonic, Integration
    from rockjit.study.paper import ALPHA_STEP, PERIODS, STUDY, after_the_fall
    rows = re.findall(r"^\s*\| (\d) \| (Housner|Mao) \| ([\d.]+) % \| (.*?); \$\\lambda > 0\$ for "
                      r"(\d+) of (\d+) \|$", CLAIMS["theory/study.md"], re.M)
    assert len(rows) == 4, rows
    for hb, law, share, motions, positive, total in rows:
        hb, law = int(hb), law.lower()
        sw = rockjit.sweep(Block(hb=float(hb), law=law), Harmonic(omega=STUDY[hb]["omega"]),
                           rockjit.alpha_grid(STUDY[hb]["alpha_range"][law], ALPHA_STEP),
                           integration=Integration(periods=PERIODS, stop_at_overturn=False),
                           lyapunov=True)
        a = after_the_fall(sw)
        assert f"{a['plotted_after_fall_percent']:.1f}" == share, (hb, law)
        quoted = {name: int(n) for n, name in re.findall(r"(\d+) (\w+)", motions)}
        assert quoted == a["motions"], (hb, law)
        assert (a["lambda_positive"], sum(quoted.values())) == (int(positive), int(total))
    short = _number(r"(\d+) % of that diagram's amplitudes plot what followed an overturn",
                    CLAIMS["study.md"]).group(1)
    assert short == f"{float(rows[1][2]):.0f}"


# ---- the study's numbers, typed once in the theory page and once in rockjit.study.report ----

def test_the_theory_pages_transitions_are_the_reports():
    # the table between the transitions markers, per (hb, law), in order, against the
    # reference values index.html prints beside each run's
    from rockjit.study.report import TRANSITIONS
    text = CLAIMS["theory/study.md"]
    table = text[text.index("<!-- transitions:begin -->"):text.index("<!-- transitions:end -->")]
    quoted, key = {}, None
    for line in table.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 3 or not re.search(r"\d\.\d{5}", cells[2]):
            continue
        if cells[0]:
            hb, law = cells[0].split(", ")
            key = (int(hb), law.split()[0].lower())
        quoted.setdefault(key, []).extend(float(v) for v in re.findall(r"\d\.\d+", cells[2]))
    reported = {}
    for hb, law, _, _, _, alpha in TRANSITIONS:
        reported.setdefault((hb, law), []).append(alpha)
    assert quoted == reported


def test_the_theory_pages_shares_after_the_fall_are_the_reports():
    from rockjit.study.report import SHARES_PUBLISHED
    rows = re.findall(r"^\s*\| (\d) \| (Housner|Mao) \| ([\d.]+) % \|", CLAIMS["theory/study.md"],
                      re.M)
    assert {(int(hb), law.lower()): float(share) for hb, law, share in rows} == SHARES_PUBLISHED


def test_the_restitution_tables_are_the_reports_and_the_laws():
    from rockjit.model import delta_e_percent, e_housner, e_mao, thc_from_hb
    from rockjit.study.report import E_TABLE_PUBLISHED
    # the Settings table of the theory page: e_H and e_M at each slenderness
    settings = re.findall(r"([\d.]+) and ([\d.]+) at \$h/b = (\d)\$",
                          _number(r"\| restitution \|[^\n]*", CLAIMS["theory/study.md"]).group(0))
    assert {float(hb): (float(eh), float(em)) for eh, em, hb in settings} == \
        {hb: (eh, em) for hb, (eh, em, _) in E_TABLE_PUBLISHED.items()}
    # the impact laws' page: e_H, e_M and delta e at each slenderness
    page = (ROOT / "docs" / "theory" / "impacts.md").read_text(encoding="utf-8")
    page = page[page.index("The study's two blocks:"):page.index("The wider table")]
    rows = re.findall(r"^\| (\d) \| [\d.]+[^|]*\| ([\d.]+) \| ([\d.]+) \| ([\d.]+) % \|$", page,
                      re.M)
    assert {float(hb): tuple(float(v) for v in rest) for hb, *rest in rows} == E_TABLE_PUBLISHED
    # and the laws themselves, to the digits quoted
    for hb, (eh, em, de) in E_TABLE_PUBLISHED.items():
        thc = thc_from_hb(hb)
        h, m = e_housner(thc), e_mao(thc)
        assert (f"{h:.3f}", f"{m:.3f}", f"{delta_e_percent(h, m):.2f}") == \
            (f"{eh:.3f}", f"{em:.3f}", f"{de:.2f}")


def test_the_theory_pages_reference_fates_are_the_reports():
    from rockjit.study.report import FATES_PUBLISHED, GIM_PUBLISHED
    text = CLAIMS["theory/study.md"]
    over, p7 = _number(r"rockjit 0\.1\.0,[^%]*?drew (\d+) % and (\d+) %", text).groups()
    assert (int(over), int(p7)) == tuple(round(100 * FATES_PUBLISHED["closed"][k])
                                         for k in ("overturn", "period-7"))
    emb = _every(r"embedded forcing[^.]*?(\d+) % overturn and (\d+) % period 7",
                 ("study.md", "theory/study.md"))
    for m in emb.values():
        assert tuple(int(v) for v in m.groups()) == tuple(
            round(100 * FATES_PUBLISHED["embedded"][k]) for k in ("overturn", "period-7"))
    mao, housner = _number(r"the mean GIM over \$\\alpha = 0\.3\$–\$0\.9\$ is ([\d.]+) against "
                           r"Housner's (\d\.\d+)", text).groups()
    assert (float(housner), float(mao)) == (GIM_PUBLISHED["housner"], GIM_PUBLISHED["mao"])


def test_the_performance_pages_count_of_deliberate_bugs_is_the_benchmarks():
    # docs/performance.md counts the bugs benchmarks/results/mutants.md lists, one row each
    page = " ".join((ROOT / "docs" / "performance.md").read_text(encoding="utf-8").split())
    quoted = int(_number(r"Mutation testing: (\d+) small bugs", page).group(1))
    text = (RESULTS / "mutants.md").read_text(encoding="utf-8")
    table = text[text.index("| mutant |"):]
    rows = [line for line in table.splitlines()[2:] if line.startswith("| ")]
    assert rows and all(line.count("|") == 8 for line in rows), rows
    assert quoted == len(rows)


def test_the_explorer_guide_quotes_the_servers_session_lifetime():
    # docs/guide/explore.md: a page's placeholder session is dropped when Bokeh's unused-session
    # lifetime runs out
    from rockjit.explorer.server import UNUSED_SESSION_MS
    page = " ".join((ROOT / "docs" / "guide" / "explore.md").read_text(encoding="utf-8").split())
    seconds = int(_number(r"its placeholder is dropped about (\d+) s later", page).group(1))
    assert seconds == round(UNUSED_SESSION_MS / 1000)
