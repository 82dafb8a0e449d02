"""Partial shapes through the Python binding, against the real library: a quadruped with its
lower third cut away is taken as a part of the whole and its mask on A follows the cut; told
the other way round (the part as A), the whole's mask marks what the part holds; a whole pair
is whole and covered."""

import numpy as np
import pytest

import shapecorr

SIZE = 3000


def cut_below(shape, share):
    """The mesh of ``shape`` without the triangles that reach into its lowest ``share`` of
    height (the figures stand along y), its vertices renumbered; and, for every kept vertex,
    its index in ``shape``."""
    vertices, triangles = shape.vertices, shape.triangles
    height = vertices[:, 1]
    floor = height.min() + share * (height.max() - height.min())
    kept_triangles = triangles[(height[triangles] > floor).all(axis=1)]
    kept = np.unique(kept_triangles)
    new_index = np.full(len(vertices), -1, dtype=np.int64)
    new_index[kept] = np.arange(len(kept))
    part = shapecorr.Shape.mesh(vertices[kept], new_index[kept_triangles])
    return part, kept


def share_right(mask, kept):
    truth = np.zeros(len(mask), dtype=bool)
    truth[kept] = True
    return float((mask == truth).mean())


@pytest.fixture(scope="module")
def quadrupeds():
    whole_a = shapecorr.Shape.figure("quadruped", 0, SIZE)
    whole_b = shapecorr.Shape.figure("quadruped", 1, SIZE)
    return whole_a, whole_b


def test_a_cut_figure_is_taken_as_a_part_and_its_mask_follows_the_cut(quadrupeds):
    a, whole_b = quadrupeds
    b, kept = cut_below(whole_b, 1 / 3)
    result = shapecorr.pointwise_map(a, b)
    assert result.taken_as == "b_in_a"
    assert result.partial_given is False
    covered_a, covered_b = result.covered_a, result.covered_b
    assert covered_a.dtype == np.bool_ and covered_a.shape == (a.n_vertices,)
    # The figures of one kind share their vertex order: B's kept vertices are A's truth.
    assert share_right(covered_a, kept) > 0.85
    assert 0.3 < result.covered_share < 0.9
    assert covered_b.all(), "every vertex of a part of A has a counterpart"


def test_the_part_as_a_marks_its_counterpart_on_the_whole(quadrupeds):
    whole_a, b = quadrupeds
    a, kept = cut_below(whole_a, 1 / 3)
    result = shapecorr.pointwise_map(a, b, partial="a_in_b")
    assert result.taken_as == "a_in_b"
    assert result.partial_given is True
    assert share_right(result.covered_b, kept) > 0.85
    assert result.covered_share > 0.9


def test_a_whole_pair_is_whole_and_covered(quadrupeds):
    a, b = quadrupeds
    result = shapecorr.pointwise_map(a, b, p2p_eigenpairs=60, p2p_zoomout_end=60)
    assert result.taken_as == "whole"
    assert result.covered_a.mean() > 0.9
    assert result.covered_b.all()
