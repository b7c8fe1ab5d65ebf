"""One threads setting: auto takes the cores the machine has free; a bad value is one line."""

from __future__ import annotations

import pytest

from robohealth_mj.common.errors import InputError
from robohealth_mj.common.threads import free_cores, resolve_threads, usable_cores


def test_auto_leaves_the_cores_other_jobs_are_using():
    cores = usable_cores()
    assert free_cores(busy=0.0) == cores
    assert free_cores(busy=cores + 5.0) == 1  # a saturated machine still gets one thread
    if cores >= 2:
        assert free_cores(busy=1.2) == cores - 1
    assert 1 <= resolve_threads("auto") <= cores and 1 <= resolve_threads(None) <= cores


@pytest.mark.parametrize("value", [0, -2, "two", "1.5", True, 2.5])
def test_a_thread_count_that_is_not_one_is_refused_naming_the_key(value):
    with pytest.raises(InputError, match=r"^threads: .* not a thread count"):
        resolve_threads(value, "threads")


def test_a_number_is_taken_as_given():
    assert resolve_threads(3) == 3 and resolve_threads("4") == 4
