"""The allocator policy: with it a freed frame-sized buffer comes back without page faults; off glibc it says no."""

import platform
import resource
import sys

import numpy as np
import pytest

from rangebearing import allocator


@pytest.mark.skipif(not sys.platform.startswith("linux") or platform.libc_ver()[0] != "glibc", reason="glibc only")
def test_a_freed_buffer_is_reused_without_faulting_its_pages_in_again():
    assert allocator.keep_freed_buffers() is True
    assert allocator.keep_freed_buffers() is True  # idempotent
    size = 2 * 2**20  # above glibc's initial 128 KiB mmap threshold: without the policy, fresh pages every time
    np.ones(size, np.uint8)  # the first one may fault in
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(40):
        np.ones(size, np.uint8)  # allocated, written, freed
    faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before
    assert faults < 64  # glibc by default trims and re-faults the heap top: ~500 faults here


def test_off_linux_nothing_is_set(monkeypatch):
    monkeypatch.setattr(allocator.sys, "platform", "darwin")
    assert allocator.keep_freed_buffers() is False
