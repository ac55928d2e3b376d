"""The pruning count behind docs/performance.md's "near what an exact kernel can do"."""

import math

import numpy as np

from studies.kernel_pruning import shares


def test_shares_partition_each_disc_and_nest_with_the_discs() -> None:
    row = shares(math.radians(20.0), 3000, seed=1)
    total = np.add(np.add(row["all_in"], row["some"]), row["none"])
    assert np.allclose(total, 1.0, atol=2e-3)  # rounded to 0.001 each
    assert list(row["discs_mrad"]) == sorted(row["discs_mrad"], reverse=True)
    # a smaller disc holds a pixel in all its copies less often, in none more often
    assert np.all(np.diff(row["all_in"]) <= 0) and np.all(np.diff(row["none"]) >= 0)


def test_the_oracle_saves_solves_but_not_most_of_them() -> None:
    row = shares(0.0, 3000, seed=2)
    assert 1.0 <= row["solves_per_pixel_oracle"] < row["solves_per_pixel_now"] <= 4.0
    # the grid's reach is most of a disc's radius: an oracle leaves more than two thirds of the solves
    assert row["solves_per_pixel_oracle"] > 0.67 * row["solves_per_pixel_now"]
