"""The allocator policy: with it a freed frame-sized buffer comes back without page faults; off glibc it says no."""

import os
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


def test_one_worker_keeps_opencv_in_the_calling_thread():
    import cv2

    before = cv2.getNumThreads()
    try:
        cv2.setNumThreads(max(2, before))
        allocator.one_worker()
        assert cv2.getNumThreads() == 1
    finally:
        cv2.setNumThreads(before)


def test_run_starts_openblas_with_one_thread_unless_told(tmp_path):
    import subprocess

    probe = ("import os, sys; from rangebearing.cli import main as m; "
             "m._run = lambda a: print(os.environ.get('OPENBLAS_NUM_THREADS')) or 0; sys.exit(m.main(sys.argv[1:]))")
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    out = [subprocess.run([sys.executable, "-c", probe, *argv], env={**env, **extra}, capture_output=True,
                          text=True, timeout=60).stdout.strip() for argv, extra in
           [(["run", "--check"], {}), (["run", "--check"], {"OPENBLAS_NUM_THREADS": "3"}), (["listen"], {})]]
    assert out == ["1", "3", "None"]
