"""Placement, landmarks and the other answer through the Python binding, against the real
library: landmarks map exactly to their partners, bad ones raise naming the pair, the verdict
names what was chosen and why, and the other answer is the runner-up's map, usable for a
transfer. Figures of one kind and size share their vertex order, so ``(v, v)`` pairs are
true landmarks."""

import math

import numpy as np
import pytest

import shapecorr
from shapecorr import ShapecorrError

SIZE = 1500
QUICK = dict(p2p_eigenpairs=60, p2p_zoomout_end=60, p2p_fmap_size=20)


@pytest.fixture(scope="module")
def humanoids():
    return shapecorr.Shape.figure("humanoid", 0, SIZE), shapecorr.Shape.figure("humanoid", 3, SIZE)


@pytest.fixture(scope="module")
def landmarks(humanoids):
    n = humanoids[1].n_vertices
    return [(n // 7, n // 7), (3 * n // 5, 3 * n // 5)]


@pytest.fixture(scope="module")
def pointwise(humanoids, landmarks):
    a, b = humanoids
    return shapecorr.pointwise_map(a, b, landmarks=landmarks, placement="ignore", **QUICK)


def test_landmarks_map_exactly_to_their_partners(pointwise, landmarks):
    mapped = pointwise.map_b_to_a
    for va, vb in landmarks:
        assert mapped[vb] == va


def test_an_array_of_landmarks_is_taken_too(humanoids, landmarks):
    a, b = humanoids
    pairs = np.array(landmarks, dtype=np.int64)
    result = shapecorr.match(a, b, landmarks=pairs, placement="ignore")
    assert result.hypothesis is not None
    assert result.decided_by in {"cost", "close call", "landmarks"}


def test_the_verdict_names_the_choice_and_the_runner_up(pointwise):
    assert pointwise.hypothesis is not None
    assert pointwise.decided_by in {"cost", "close call", "landmarks"}
    assert pointwise.placement_used is False
    chosen, runner_up = pointwise.chosen, pointwise.runner_up
    assert chosen is not None and chosen.hypothesis == pointwise.hypothesis
    assert runner_up is not None, "a humanoid pair has a runner-up (its mirror image at least)"
    assert runner_up.hypothesis != chosen.hypothesis
    for h in (chosen, runner_up):
        assert math.isfinite(h.cost) and h.cost >= 0
        assert 0.0 <= h.turn_degrees <= 180.0
    assert pointwise.turn_degrees == chosen.turn_degrees
    # The regions carry the same verdict.
    assert pointwise.regions.hypothesis == pointwise.hypothesis
    assert pointwise.regions.runner_up == runner_up


def test_the_other_answer_is_the_runner_ups_map_and_transfers(humanoids, pointwise, landmarks):
    a, b = humanoids
    other = pointwise.other_answer()
    assert isinstance(other, shapecorr.PointwiseMap)
    assert other.decided_by == "other answer"
    assert other.hypothesis == pointwise.runner_up.hypothesis
    assert other.chosen.cost == pointwise.runner_up.cost
    first, second = pointwise.map_b_to_a, other.map_b_to_a
    assert np.mean(first != second) > 0.1, "the other answer moves a tenth of B at least"
    for va, vb in landmarks:
        assert second[vb] == va
    # A transfer through the other answer carries A's coordinates to where it says.
    onto = shapecorr.surface_map(a, b, other)
    carried = onto.transfer(a.vertices, mode="nearest")
    assert np.array_equal(carried, a.vertices[onto.nearest])
    assert np.linalg.norm(carried - a.vertices[second], axis=1).mean() < np.linalg.norm(
        carried - a.vertices[first], axis=1
    ).mean()
    regions = pointwise.regions.other_answer()
    assert isinstance(regions, shapecorr.Correspondence)
    assert regions.decided_by == "other answer"


def test_an_unverified_answer_has_no_verdict_and_no_other_answer(humanoids):
    a, b = humanoids
    result = shapecorr.match(a, b, verify_hypotheses=False)
    assert result.hypothesis is None and result.decided_by is None
    assert result.turn_degrees is None and result.runner_up is None and result.chosen is None
    assert result.placement_used is False
    assert result.other_answer() is None


@pytest.mark.parametrize("placement", ["auto", "ignore", "trust", "TRUST", 0, 1, 2])
def test_every_placement_is_accepted(placement):
    params = shapecorr._Params({"placement": placement})
    value = shapecorr.ctypes.c_int64()
    shapecorr._check(shapecorr.lib.sc_params_get_int(params, b"placement", shapecorr.ctypes.byref(value)))
    expected = {"auto": 0, "ignore": 1, "trust": 2}.get(str(placement).lower(), placement)
    assert value.value == expected


@pytest.mark.parametrize("placement", ["sideways", 3, -1])
def test_an_unknown_placement_raises(humanoids, placement):
    a, b = humanoids
    with pytest.raises(ShapecorrError) as error:
        shapecorr.match(a, b, placement=placement)
    assert error.value.status_name == "INVALID_PARAMETER"
    assert "placement" in error.value.message


def test_bad_landmarks_raise_naming_the_pair(humanoids):
    a, b = humanoids
    n = b.n_vertices
    cases = [
        ([(1, 1), (2, n + 5)], ["pair 2", str(n + 5)]),  # past the end of B
        ([(1, 1), (1, 7)], ["pairs 1", "contradict"]),  # one vertex of A, two partners
        ([(4, 4), (-3, 5)], ["pair 2", "-3"]),  # negative
    ]
    for pairs, words in cases:
        for call in (shapecorr.match, shapecorr.pointwise_map):
            with pytest.raises(ShapecorrError) as error:
                call(a, b, landmarks=pairs)
            assert error.value.status_name == "INVALID_PARAMETER", pairs
            assert "landmarks" in error.value.message
            for word in words:
                assert word in error.value.message, (pairs, error.value.message)
    with pytest.raises(ShapecorrError) as error:
        shapecorr.match(a, b, landmarks=[(i, i) for i in range(101)])
    assert "at most 100" in error.value.message


@pytest.mark.parametrize(
    "pairs",
    [
        [(True, 3)],
        [(1.0, 3)],
        [(1, "3")],
        [(1, 2, 3)],
        [5],
        "12",
        np.array([[1.5, 2.0]]),
        np.array([[True, False]]),
        np.array([1, 2, 3]),
    ],
)
def test_landmarks_of_the_wrong_type_raise_type_error(humanoids, pairs):
    a, b = humanoids
    with pytest.raises(TypeError) as error:
        shapecorr.match(a, b, landmarks=pairs)
    assert isinstance(error.value, ShapecorrError)
    assert error.value.status_name == "INVALID_ARGUMENT"
    assert "landmarks" in error.value.message


def test_no_landmarks_is_the_default(humanoids):
    """An empty list sets none: the answer is the one without the argument."""
    a, b = humanoids
    plain = shapecorr.match(a, b, placement="ignore")
    empty = shapecorr.match(a, b, landmarks=[], placement="ignore")
    assert np.array_equal(plain.matches_one_to_one, empty.matches_one_to_one)
    assert plain.hypothesis == empty.hypothesis
