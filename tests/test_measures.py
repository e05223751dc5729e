"""Tests of rockjit.measures against hand-computed values, closed forms and slow references.

The maps are synthetic (half-planes, checkerboards, discs, strips, seeded noise), so every
expected value is worked out here by hand or by a readable loop that shares no code with the
module: box entropies from counted cells, uncertain fractions from the geometry of a straight
boundary, disc radii from the geometry of the safe set.
"""

from __future__ import annotations

import json
import math
from collections import Counter

import numpy as np
import pytest
from scipy import stats

from rockjit.measures import (
    basin_entropy, integrity, uncertain_fraction, uncertain_fraction_sampled,
    uncertainty_exponent,
)


def h2(*counts):
    """Entropy (nats) of a box with the given cell counts, written out by hand."""
    total = sum(counts)
    return -sum(c / total * math.log(c / total) for c in counts if c)


# --------------------------------------------------------------------------- basin entropy

def test_half_plane_entropy_counts_the_straddling_boxes():
    # 20 x 20, columns 0-6 -> 0, 7-19 -> 1. Box columns are 0-4, 5-9, 10-14, 15-19: only the
    # second straddles the boundary, with 2 columns of 0 and 3 of 1 in each of its 4 boxes.
    ids = np.zeros((20, 20), dtype=int)
    ids[:, 7:] = 1
    res = basin_entropy(ids, box=5)
    s = h2(10, 15)
    assert res.n_boxes == 16 and res.n_boundary == 4
    assert res.Sb == pytest.approx(4 * s / 16, rel=1e-14)
    assert res.Sbb == pytest.approx(s, rel=1e-14)
    sb, sbb = res                                   # unpacks as the pair
    assert (sb, sbb) == (res.Sb, res.Sbb)


def test_boundary_on_box_edges_gives_no_boundary_box():
    # the same half-plane with the boundary between columns 9 and 10: no box straddles it, so
    # overlapping or shifted boxes would be caught here
    ids = np.zeros((20, 20), dtype=int)
    ids[:, 10:] = 1
    res = basin_entropy(ids, box=5)
    assert res.Sb == 0.0 and res.n_boundary == 0 and math.isnan(res.Sbb)


def test_checkerboard_every_box_splits_13_12():
    ids = np.indices((25, 25)).sum(axis=0) % 2
    res = basin_entropy(ids, box=5)
    s = h2(13, 12)
    assert res.n_boxes == res.n_boundary == 25
    assert res.Sb == pytest.approx(s, rel=1e-14)
    assert res.Sbb == pytest.approx(s, rel=1e-14)
    assert res.Sbb < math.log(2)                    # 13/12 is nearly, not exactly, even


def test_constant_map_has_zero_entropy_and_undefined_boundary_entropy():
    res = basin_entropy(np.full((15, 10), 3), box=5)
    assert res.Sb == 0.0
    assert math.isnan(res.Sbb)                      # the documented convention
    assert res.n_boundary == 0 and res.n_boxes == 6
    assert math.isnan(res.to_dict()["boundary_basin_entropy"])


def test_three_outcomes_in_one_box_overturn_and_unresolved_included():
    ids = np.zeros((10, 10), dtype=int)
    box = ids[:5, :5]                               # a view: fills the top-left box
    box[:2, :] = 2                                  # 10 cells attractor 2
    box[2:4, :] = -1                                # 10 cells overturn
    box[4, :] = -2                                  # 5 cells unresolved
    res = basin_entropy(ids, box=5)
    s = -(2 * 0.4 * math.log(0.4) + 0.2 * math.log(0.2))
    assert res.n_boundary == 1 and res.n_boxes == 4
    assert res.Sb == pytest.approx(s / 4, rel=1e-14)
    assert res.Sbb == pytest.approx(s, rel=1e-14)


def test_remainder_rows_and_columns_are_dropped():
    # 12 x 13 with box 5: the boxes cover rows 0-9 and columns 0-9; outcomes that differ only
    # in the left-over strips must not count
    ids = np.zeros((12, 13), dtype=int)
    ids[10:, :] = 1
    ids[:, 10:] = 2
    res = basin_entropy(ids, box=5)
    assert res.n_boxes == 4 and res.Sb == 0.0 and res.n_boundary == 0
    ids[9, 9] = 7                                   # inside the last full box: counts
    res = basin_entropy(ids, box=5)
    assert res.n_boundary == 1
    assert res.Sb == pytest.approx(h2(24, 1) / 4, rel=1e-14)


def slow_entropy(ids, b):
    """Readable reference: loop over the full boxes, count with Counter."""
    ent = []
    for r in range(0, ids.shape[0] - b + 1, b):
        for c in range(0, ids.shape[1] - b + 1, b):
            ent.append(h2(*Counter(ids[r:r + b, c:c + b].ravel().tolist()).values()))
    bnd = [s for s in ent if s > 0]
    return sum(ent) / len(ent), (sum(bnd) / len(bnd) if bnd else math.nan)


@pytest.mark.parametrize("shape, b, k, patch", [((23, 31), 5, 3, 1), ((40, 40), 4, 7, 1),
                                               ((9, 17), 3, 40, 1), ((42, 36), 4, 3, 6)])
def test_entropy_matches_a_slow_reference_on_random_maps(shape, b, k, patch):
    # patch > 1: the map is made of patch x patch squares of one outcome, so that some boxes
    # hold one outcome and others straddle a square's edge (Sbb differs from Sb)
    n, m = -(-shape[0] // patch), -(-shape[1] // patch)
    coarse = np.random.default_rng(7).integers(-2, k, size=(n, m))
    ids = np.kron(coarse, np.ones((patch, patch), dtype=int))[:shape[0], :shape[1]]
    sb, sbb = basin_entropy(ids, box=b)
    ref_sb, ref_sbb = slow_entropy(ids, b)
    if patch > 1:
        assert 0 < ref_sb < ref_sbb
    assert sb == pytest.approx(ref_sb, rel=1e-12)
    assert sbb == pytest.approx(ref_sbb, rel=1e-12)


@pytest.mark.parametrize("ids, box, word", [
    (np.zeros((10, 10), int), 1, "box"),
    (np.zeros((10, 10), int), 11, "box"),
    (np.zeros((10, 10), int), 2.5, "box"),
    (np.zeros((10, 10)), 5, "ids"),                 # float ids
    (np.zeros(10, int), 5, "ids"),                  # 1-D
])
def test_entropy_rejects_bad_input_by_name(ids, box, word):
    with pytest.raises(ValueError, match=word):
        basin_entropy(ids, box=box)


# --------------------------------------------------------------------------- uncertainty, grid

EPS = [1, 2, 4, 8, 16]


def test_uncertain_fraction_by_hand_on_a_single_odd_cell():
    ids = np.zeros((5, 5), dtype=int)
    ids[2, 2] = 1
    # eps 1, margin 1: interior 3x3; the odd cell and its 4 axis neighbours are uncertain
    assert uncertain_fraction(ids, 1) == pytest.approx(5 / 9, rel=1e-15)
    # eps 1 with margin 2: only the centre is counted, and it differs from its neighbours
    assert uncertain_fraction(ids, 1, margin=2) == 1.0
    # a diagonal neighbour is not a perturbation of the centre: margin 1, eps 1, cell (1, 1)
    ids2 = np.zeros((5, 5), dtype=int)
    ids2[1, 1] = 1
    # uncertain: (1,1), (2,1), (1,2); (2,2) is diagonal to it and stays certain
    assert uncertain_fraction(ids2, 1) == pytest.approx(3 / 9, rel=1e-15)


@pytest.mark.parametrize("slope", [0.0, 0.37])
def test_straight_boundary_fraction_and_exponent_one(slope):
    # Boundary j = 60 + slope * i with |slope| < 1: along each row it crosses once, so the
    # horizontal perturbations make exactly 2 eps cells of that row uncertain, and a vertical
    # one moves the boundary by slope * eps < eps, inside that stretch. With margin 16 the 168
    # interior rows each hold 2 eps uncertain cells of 168: f = 2 eps / 168 exactly, and the
    # log-log slope is 1 to rounding.
    n = 200
    i, j = np.indices((n, n))
    ids = (j - slope * i > 60 + 0.5).astype(np.int64)  # +0.5: no cell exactly on the line
    f = uncertain_fraction(ids, EPS)
    np.testing.assert_allclose(f, 2 * np.array(EPS) / 168, rtol=1e-14)
    alpha, se, dim = uncertainty_exponent(EPS, f)
    assert alpha == pytest.approx(1.0, abs=1e-12)
    assert dim == pytest.approx(1.0, abs=1e-12)
    assert se < 1e-12


def test_random_map_fraction_is_flat_and_exponent_zero():
    # i.i.d. ids in {0, 1}: a cell is certain only when its four perturbed neighbours all share
    # its outcome, probability 2^-4, whatever eps: f = 15/16 for every eps, so alpha = 0.
    # 168^2 = 28224 cells give a binomial standard error of 0.0014 on f (0.15 % relative), so
    # over the ln(16) = 2.8 span of eps the slope wanders by about 1e-3; 0.01 is a wide margin
    # that still tells noise (alpha ~ 0) from any boundary of dimension < 1.99.
    ids = np.random.default_rng(3).integers(0, 2, size=(200, 200))
    f = uncertain_fraction(ids, EPS)
    se_f = math.sqrt(15 / 16 / 16 / 168**2)
    assert np.all(np.abs(f - 15 / 16) < 5 * se_f)
    fit = uncertainty_exponent(EPS, f)
    assert abs(fit.alpha) < 0.01
    assert fit.dimension == pytest.approx(2.0, abs=0.01)


def test_uncertain_fraction_scalar_and_validation():
    ids = np.zeros((10, 10), dtype=int)
    f = uncertain_fraction(ids, 2)
    assert isinstance(f, float) and f == 0.0  # one outcome: nothing is uncertain
    # a straight boundary between columns 4 and 5, counted by hand over the interior rows and
    # columns 2..7 (margin 2): at eps = 1 the two columns beside it are uncertain, at eps = 2
    # the four nearest
    ids[:, 5:] = 7
    assert uncertain_fraction(ids, 2) == 4 / 6
    assert uncertain_fraction(ids.T, 2) == 4 / 6
    np.testing.assert_array_equal(uncertain_fraction(ids, (1, 2)), [2 / 6, 4 / 6])
    with pytest.raises(ValueError, match="eps_cells"):
        uncertain_fraction(ids, 0)
    with pytest.raises(ValueError, match="eps_cells"):
        uncertain_fraction(ids, 1.5)
    with pytest.raises(ValueError, match="margin"):
        uncertain_fraction(ids, 3, margin=2)        # margin below eps
    with pytest.raises(ValueError, match="margin"):
        uncertain_fraction(ids, 5)                  # no interior left
    with pytest.raises(ValueError, match="ids"):
        uncertain_fraction(np.zeros((10, 10)), 1)


# --------------------------------------------------------------------------- exponent fit

def test_exponent_fit_matches_scipy_linregress():
    rng = np.random.default_rng(11)
    eps = np.geomspace(1e-3, 1e-1, 9)
    f = 0.4 * eps**0.63 * np.exp(0.05 * rng.standard_normal(eps.size))
    fit = uncertainty_exponent(eps, f)
    ref = stats.linregress(np.log(eps), np.log(f))
    assert fit.alpha == pytest.approx(ref.slope, rel=1e-12)
    assert fit.stderr == pytest.approx(ref.stderr, rel=1e-10)
    assert fit.intercept == pytest.approx(ref.intercept, rel=1e-12)
    assert fit.dimension == pytest.approx(2 - ref.slope, rel=1e-12)
    assert uncertainty_exponent(eps, f, dim=3).dimension == pytest.approx(3 - ref.slope)


def test_exact_power_law():
    eps = [0.01, 0.03, 0.1, 0.3]
    fit = uncertainty_exponent(eps, [0.5 * e**0.7 for e in eps])
    assert fit.alpha == pytest.approx(0.7, abs=1e-13)
    assert math.exp(fit.intercept) == pytest.approx(0.5, rel=1e-12)


@pytest.mark.parametrize("eps, f, word", [
    ([1, 2], [0.1, 0.2], "eps"),                    # too few points for a standard error
    ([1, 2, 4], [0.1, 0.2], "f"),                   # shape
    ([1, 2, 4], [0.1, 0.0, 0.3], "f"),              # a zero fraction has no logarithm
    ([1, 2, 4], [0.1, 0.2, 1.5], "f"),
    ([1, -2, 4], [0.1, 0.2, 0.3], "eps"),
    ([2, 2, 2], [0.1, 0.2, 0.3], "eps"),            # no spread in eps
])
def test_exponent_rejects_bad_input_by_name(eps, f, word):
    with pytest.raises(ValueError, match=word):
        uncertainty_exponent(eps, f)


# --------------------------------------------------------------------------- uncertainty, sampled

SEPS = np.array([0.01, 0.02, 0.04, 0.08, 0.16])


def test_sampled_half_plane_matches_the_closed_form():
    # Boundary theta = 0.3 in the box [-1, 1] x [-3, 5], at u* = 0.65 in normalised units; base
    # points uniform in [0.16, 0.84]^2. A point at normalised distance d from the boundary is
    # uncertain when eps |cos phi| > d (the + or the - perturbation crosses), so
    # f = E[2 eps |cos phi|] / 0.68 = 4 eps / (0.68 pi) exactly (u* +- 0.16 stays inside).
    seen = []

    def outcome(points):
        seen.append(points.copy())
        return (points[:, 0] > 0.3).astype(np.int64)

    res = uncertain_fraction_sampled(outcome, (-1, -3), (1, 5), SEPS, n=100_000, seed=0)
    assert len(seen) == 1 and seen[0].shape == (100_000 * 11, 2)
    pts = seen[0]                                   # every perturbed point stays in the box
    assert pts[:, 0].min() >= -1 and pts[:, 0].max() <= 1
    assert pts[:, 1].min() >= -3 and pts[:, 1].max() <= 5
    ref = 4 * SEPS / (0.68 * math.pi)
    assert np.all(np.abs(res.f - ref) < 4 * res.stderr)
    # The smallest eps has ~1900 uncertain points (2.3 % relative error); over the ln(16) span
    # that moves the slope by about 0.01 (seeds 0-4 give 0.989-1.006): 0.05 is 4-5 sigma.
    assert res.exponent().alpha == pytest.approx(1.0, abs=0.05)


def test_sampled_fine_stripes_give_a_flat_fraction():
    # stripes 1e-5 wide in theta, far below the smallest perturbation: the two perturbed points
    # land on each parity independently of the base point, so a point is certain with
    # probability 1/4 and f = 3/4 at every eps: alpha = 0 (a riddled-like map)
    res = uncertain_fraction_sampled(
        lambda p: np.floor(p[:, 0] * 1e5).astype(np.int64) % 2, (-1, -3), (1, 5), SEPS,
        n=20_000, seed=1)
    assert np.all(np.abs(res.f - 0.75) < 5 * math.sqrt(0.75 * 0.25 / 20_000))
    assert abs(res.exponent().alpha) < 0.05


def test_sampled_is_reproducible_from_its_seed():
    def outcome(p):
        return (p[:, 0] ** 2 + p[:, 1] ** 2 < 0.5).astype(np.int64)

    a = uncertain_fraction_sampled(outcome, (-1, -1), (1, 1), [0.05, 0.1], n=2000, seed=5)
    b = uncertain_fraction_sampled(outcome, (-1, -1), (1, 1), [0.05, 0.1], n=2000, seed=5)
    c = uncertain_fraction_sampled(outcome, (-1, -1), (1, 1), [0.05, 0.1], n=2000, seed=6)
    np.testing.assert_array_equal(a.uncertain, b.uncertain)
    assert not np.array_equal(a.uncertain, c.uncertain)


@pytest.mark.parametrize("kwargs, word", [
    (dict(outcome=lambda p: np.zeros(3, int)), "outcome"),          # wrong length
    (dict(outcome=lambda p: np.zeros(len(p))), "outcome"),          # float ids
    (dict(outcome=42), "outcome"),
    (dict(lo=(1, 0)), "hi"),
    (dict(lo=(0, 0, 0)), "lo"),
    (dict(eps=0.5), "eps"),
    (dict(eps=[0.1, -0.1]), "eps"),
    (dict(n=0), "n"),
    (dict(seed=1.5), "seed"),
])
def test_sampled_rejects_bad_input_by_name(kwargs, word):
    args = dict(outcome=lambda p: np.zeros(len(p), int), lo=(0, 0), hi=(1, 1), eps=0.1, n=10)
    args.update(kwargs)
    with pytest.raises(ValueError, match=word):
        uncertain_fraction_sampled(args.pop("outcome"), **args)


# --------------------------------------------------------------------------- integrity

AX = np.linspace(-1.0, 1.0, 201)                    # spacing 0.01, a node at 0
H = 0.01


def grid(theta, dtheta):
    return np.meshgrid(theta, dtheta, indexing="ij")


def test_disc_shaped_safe_basin():
    # safe disc of radius 0.6 around (0.1, -0.05) in [-1, 1]^2; the rest overturns
    r0, c = 0.6, (0.1, -0.05)
    t, d = grid(AX, AX)
    ids = np.where((t - c[0]) ** 2 + (d - c[1]) ** 2 <= r0**2, 0, -1)
    res = integrity(ids, AX, AX, points={0: [c]})
    # GIM: the disc's area over the area the 201^2 cells stand for, within one ring of cells
    area = (201 * H) ** 2
    assert res.GIM == pytest.approx(math.pi * r0**2 / area, abs=2 * math.pi * r0 * H / area)
    # IF: the largest safe disc is the basin itself; half-width 1
    assert res.half_width == pytest.approx(1.0, rel=1e-14)
    assert abs(res.IF - r0) <= H
    assert abs(res.centre[0] - c[0]) <= H and abs(res.centre[1] - c[1]) <= H
    # LIM of a point attractor at the centre: the disc's radius
    assert abs(res.LIM[0] - r0) <= H


def test_lim_of_a_cycle_is_its_most_exposed_point():
    # safe disc as above; a 2-cycle with one point at the centre (radius 0.6) and one 0.3 from
    # the centre (0.3 from the unsafe set): the LIM is the smaller, 0.3. The off-centre point
    # is between nodes, so its distance is measured from the point itself.
    r0, c = 0.6, (0.1, -0.05)
    t, d = grid(AX, AX)
    ids = np.where((t - c[0]) ** 2 + (d - c[1]) ** 2 <= r0**2, 0, -1)
    off = (c[0] + 0.3 / math.sqrt(2), c[1] + 0.3 / math.sqrt(2))
    res = integrity(ids, AX, AX, points={0: [c, off], 1: [off]})
    assert abs(res.LIM[0] - 0.3) <= H
    assert res.LIM[0] == res.LIM[1]


def test_half_plane_safe_basin():
    # safe where theta < 0.195: 120 of the 201 theta lines (-1.00 ... 0.19). The largest disc
    # inside both the safe half and the region touches the left edge and the boundary:
    # radius (0.2 - (-1)) / 2 = 0.6, centred on theta = -0.4, a node.
    t, _ = grid(AX, AX)
    ids = np.where(t < 0.195, 2, -1)
    res = integrity(ids, AX, AX)
    assert res.GIM == pytest.approx(120 / 201, rel=1e-14)
    assert res.IF == pytest.approx(0.6, abs=1e-12)
    assert res.centre[0] == pytest.approx(-0.4, abs=1e-12)
    assert res.LIM == {}


def test_all_safe_and_all_unsafe_maps():
    res = integrity(np.zeros((201, 201), int), AX, AX)
    assert res.GIM == 1.0 and res.IF == pytest.approx(1.0, abs=1e-12)   # a node at the centre
    ax = np.linspace(-1, 1, 200)                    # no centre node: within one spacing
    res = integrity(np.zeros((200, 200), int), ax, ax)
    assert 1 - (ax[1] - ax[0]) <= res.IF < 1.0
    res = integrity(np.full((201, 201), -1), AX, AX, points={0: [(0.005, 0.005)]})
    assert res.GIM == 0.0 and res.IF == 0.0 and res.centre is None
    assert res.LIM == {0: 0.0}                      # its cell overturns


def test_unresolved_cells_are_not_safe():
    t, _ = grid(AX, AX)
    ids = np.where(t < 0.195, 0, -2)                # the half-plane again, but unresolved
    res = integrity(ids, AX, AX)
    assert res.GIM == pytest.approx(120 / 201, rel=1e-14)
    assert res.IF == pytest.approx(0.6, abs=1e-12)


def test_unequal_spacing_uses_state_units():
    # theta spacing 0.01 on [-0.5, 0.5], theta' spacing 0.02 on [-2, 2]: half-width 0.5.
    th = np.linspace(-0.5, 0.5, 101)
    dth = np.linspace(-2.0, 2.0, 201)
    t, d = grid(th, dth)
    # a disc of radius 0.3 in state units: IF = 0.3 / 0.5 (in index units it would be an
    # ellipse of semi-axes 30 and 15 cells, and a radius counted in cells would be wrong)
    res = integrity(np.where(t**2 + d**2 <= 0.09, 0, -1), th, dth, points={0: [(0.0, 0.0)]})
    assert abs(res.IF * 0.5 - 0.3) <= 0.02
    assert abs(res.LIM[0] * 0.5 - 0.3) <= 0.02
    # a strip theta' > 1.6 (0.4 wide) across the whole theta range: radius 0.2, IF 0.4
    res = integrity(np.where(d > 1.61, 0, -1), th, dth)
    assert res.IF == pytest.approx(0.4, abs=1e-12)
    # the same strip along theta instead: theta > 0.3 (0.2 wide): radius 0.1, IF 0.2
    res = integrity(np.where(t > 0.305, 0, -1), th, dth)
    assert res.IF == pytest.approx(0.2, abs=1e-12)


def slow_if(ids, th, dth):
    """Readable reference: every safe node against every unsafe node and the region's edge."""
    best = 0.0
    unsafe = [(th[i], dth[j]) for i in range(len(th)) for j in range(len(dth)) if ids[i, j] < 0]
    for i in range(len(th)):
        for j in range(len(dth)):
            if ids[i, j] < 0:
                continue
            r = min(th[i] - th[0], th[-1] - th[i], dth[j] - dth[0], dth[-1] - dth[j])
            for u in unsafe:
                r = min(r, math.hypot(th[i] - u[0], dth[j] - u[1]))
            best = max(best, r)
    return best


def test_integrity_factor_matches_a_brute_force_search():
    rng = np.random.default_rng(2)
    th = np.linspace(0.0, 1.0, 23)
    dth = np.linspace(-3.0, 1.0, 31)
    ids = np.where(rng.random((23, 31)) < 0.93, 0, -1)
    res = integrity(ids, th, dth)
    assert res.radius == pytest.approx(slow_if(ids, th, dth), rel=1e-12)
    assert res.IF == pytest.approx(res.radius / 0.5, rel=1e-14)


def test_lim_own_basin_and_outside_points():
    # left half attractor 0, right half attractor 1, both safe: the safe LIM of a point 0.3
    # left of the 0/1 boundary is bounded by the region's edge (0.5 below it in theta'), the own
    # LIM by the boundary with attractor 1
    t, _ = grid(AX, AX)
    ids = np.where(t < 0.195, 0, 1)                 # boundary between theta 0.19 and 0.20
    p = {0: [(-0.1, -0.5)]}
    assert integrity(ids, AX, AX, points=p).LIM[0] == pytest.approx(0.5, abs=1e-12)
    own = integrity(ids, AX, AX, points=p, lim_basin="own").LIM[0]
    assert own == pytest.approx(0.3, abs=1e-12)     # nearest cell of attractor 1: theta 0.20
    # a cycle point outside the sampled region: the map says nothing there
    assert math.isnan(integrity(ids, AX, AX, points={0: [(0.0, 0.0), (1.5, 0.0)]}).LIM[0])


def test_integrity_serialises_to_json():
    t, _ = grid(AX, AX)
    ids = np.where(t < 0.195, 3, -1)
    d = integrity(ids, AX, AX, points={3: np.array([[-0.4, 0.0]])}).to_dict()
    assert set(d) == {"GIM", "IF", "LIM"}
    back = json.loads(json.dumps(d))
    assert back["LIM"] == {"3": pytest.approx(0.6, abs=1e-12)}
    assert all(type(v) is float for v in (d["GIM"], d["IF"], d["LIM"][3]))


@pytest.mark.parametrize("kwargs, word", [
    (dict(ids=np.zeros((201, 201))), "ids"),
    (dict(ids=np.full((201, 201), -3)), "ids"),
    (dict(theta=AX[:-1]), "theta"),
    (dict(theta=AX[::-1]), "theta"),
    (dict(theta=np.r_[AX[:100], AX[100:] + 0.001]), "theta"),   # not uniform
    (dict(dtheta=np.full(201, np.nan)), "dtheta"),
    (dict(points=[[0, 0]]), "points"),
    (dict(points={0: [0.0, 0.0]}), "points"),
    (dict(points={-1: [[0.0, 0.0]]}), "points"),
    (dict(points={0: [[0.0, np.inf]]}), "points"),
    (dict(lim_basin="mine"), "lim_basin"),
])
def test_integrity_rejects_bad_input_by_name(kwargs, word):
    args = dict(ids=np.zeros((201, 201), int), theta=AX, dtheta=AX)
    args.update(kwargs)
    with pytest.raises(ValueError, match=word):
        integrity(**args)


def slow_lim(ids, th, dth, cycle, own=None):
    """Readable reference for the LIM, from its definition: for each cycle point, ``nan`` if it
    lies outside the sampled rectangle, 0 if the node nearest to it (searched over every node,
    Euclidean in state units) is outside the basin, else the smaller of its distance to the
    region's edge and to the nearest node outside the basin; the LIM is the smallest over the
    points, over the half-width. The basin is the safe cells, or the cells of ``own``."""
    inside = [[(ids[i, j] >= 0) if own is None else (ids[i, j] == own)
               for j in range(len(dth))] for i in range(len(th))]
    nodes = [(th[i], dth[j], inside[i][j]) for i in range(len(th)) for j in range(len(dth))]
    half = min(th[-1] - th[0], dth[-1] - dth[0]) / 2
    worst = math.inf
    for x, v in cycle:
        if not (th[0] <= x <= th[-1] and dth[0] <= v <= dth[-1]):
            return math.nan
        nearest = min(nodes, key=lambda nd: math.hypot(nd[0] - x, nd[1] - v))
        if not nearest[2]:
            r = 0.0
        else:
            r = min(x - th[0], th[-1] - x, v - dth[0], dth[-1] - v)
            for nx, nv, ok in nodes:
                if not ok:
                    r = min(r, math.hypot(nx - x, nv - v))
        worst = min(worst, r)
    return worst / half


@pytest.mark.parametrize("seed, unsafe, lim_basin", [(3, 0.10, "safe"), (4, 0.25, "safe"),
                                                     (5, 0.15, "own"), (6, 0.40, "own")])
def test_lim_matches_a_brute_force_reference_between_nodes(seed, unsafe, lim_basin):
    # random maps of two attractors and overturning cells on unequal spacings; the points lie
    # between nodes, most of them nearer to the node above (in theta, theta' or both) than to
    # the one below, where rounding to the nearest node and truncating to the one below differ
    rng = np.random.default_rng(seed)
    th = np.linspace(-0.6, 0.9, 16)
    dth = np.linspace(-2.0, 1.0, 13)
    h0, h1 = th[1] - th[0], dth[1] - dth[0]
    ids = np.where(rng.random((16, 13)) < unsafe, -1, rng.integers(0, 2, (16, 13)))
    frac = [(0.3, 0.2), (0.7, 0.2), (0.2, 0.8), (0.75, 0.65), (0.55, 0.45)]
    points = {}
    for n in range(40):
        i, j = rng.integers(0, 15), rng.integers(0, 12)
        fi, fj = frac[n % len(frac)]
        points[n] = [(th[i] + fi * h0, dth[j] + fj * h1)]
    # 2- and 3-cycles: the most exposed point decides
    for n in range(40, 50):
        k = rng.integers(0, 40, size=2 + n % 2)
        points[n] = [points[int(q)][0] for q in k]
    differs = 0
    for n, cyc in points.items():
        key = n % 2
        own = None if lim_basin == "safe" else key
        got = integrity(ids, th, dth, points={key: cyc}, lim_basin=lim_basin).LIM[key]
        assert got == pytest.approx(slow_lim(ids, th, dth, cyc, own), rel=1e-12, abs=1e-15), \
            (n, cyc)
        # count the points whose node below (a truncated index) and nearest node differ in
        # whether they lie in the basin
        x, v = cyc[0]
        lower = (int((x - th[0]) // h0), int((v - dth[0]) // h1))
        near = (int(round((x - th[0]) / h0)), int(round((v - dth[0]) / h1)))
        in_basin = (ids >= 0) if own is None else (ids == own)
        differs += bool(in_basin[lower] != in_basin[near])
    assert differs >= 5  # enough points where the two choices disagree on safety
