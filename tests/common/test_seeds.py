"""The named random streams: no two draw the same numbers from one seed, and every draw in the
package goes through them."""

import re
from itertools import combinations
from pathlib import Path

import numpy as np

import robohealth_mj
from robohealth_mj.common.seeds import STREAMS, stream


def test_no_two_streams_share_an_id():
    ids = list(STREAMS.values())
    assert len(ids) == len(set(ids)), sorted(ids)


def test_no_two_streams_draw_the_same_numbers_at_any_pass_or_visit():
    """With SeedSequence's zero padding, [seed, k] equals [seed, k, 0]: compare real draws of
    each stream alone and at its first indices."""
    for seed in (0, 7, 42, 900):
        draws = {}
        for name in STREAMS:
            for index in ((), (0,), (1,)):
                draws[(name, index)] = stream(name, seed, *index).integers(0, 2**62, 4).tolist()
        for (a, da), (b, db) in combinations(draws.items(), 2):
            if a[0] != b[0]:
                assert da != db, (seed, a, b)


def test_a_stream_is_the_key_it_always_was():
    """Recordings made before the table stay byte for byte: the ids kept their keys."""
    expected = np.random.default_rng([11, 1, 3]).random(3)
    np.testing.assert_array_equal(stream("curriculum.segment", 11, 3).random(3), expected)


def test_every_seeded_draw_in_the_package_goes_through_the_table():
    package = Path(robohealth_mj.__file__).parent
    keyed = re.compile(r"default_rng\(\[")
    bypass = [
        str(p.relative_to(package))
        for p in package.rglob("*.py")
        if p.name != "seeds.py" and keyed.search(p.read_text())
    ]
    assert not bypass, bypass
