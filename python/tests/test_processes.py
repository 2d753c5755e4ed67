"""The process around texel: memory limits are refused with MemoryError before anything is
allocated, and forked children (os.fork, multiprocessing's fork start method) run texel calls on
threads of their own."""

import multiprocessing
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import texel

# Figures of a budget's refusal: the need and the limit, each in MiB.
REFUSAL = r"needs about \d+\.\d MiB.*over the memory limit of \d+\.\d MiB"


def run_limited(code, address_space=4 << 30):
    """Run ``code`` in a fresh interpreter whose address space is limited (RLIMIT_AS)."""
    prelude = (
        "import resource\n"
        f"resource.setrlimit(resource.RLIMIT_AS, ({address_space}, {address_space}))\n"
        "import numpy as np\n"
        "import texel\n"
    )
    return subprocess.run(
        [sys.executable, "-c", prelude + code], capture_output=True, text=True, timeout=300
    )


def test_a_texture_over_the_address_space_limit_is_a_memory_error():
    # The array costs nothing until touched; its texture needs several times its size.
    code = (
        "a = np.zeros((16384, 16384, 4), np.uint8)\n"
        "for make in (lambda: texel.Texture(a), lambda: texel.warp(a, [0, 0, 9, 0, 9, 9, 0, 9], size=(8, 8))):\n"
        "    try:\n"
        "        make()\n"
        "        print('made')\n"
        "    except MemoryError as e:\n"
        "        print('MemoryError:', e)\n"
        "small = texel.Texture(np.zeros((1024, 1024, 4), np.uint8))\n"
        "print('small', small.width, small.height)\n"
    )
    done = run_limited(code)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert len(lines) == 3, done.stdout
    for line in lines[:2]:
        assert line.startswith("MemoryError: a 16384x16384 RGBA8 texture"), line
        assert __import__("re").search(REFUSAL, line), line
        assert "address-space limit (ulimit -v)" in line, line
    # What fits is not refused.
    assert lines[2] == "small 1024 1024"


def test_max_memory_bounds_every_entry_that_allocates_with_its_input():
    a = np.zeros((64, 64, 4), np.uint8)
    with pytest.raises(MemoryError, match=r"a 64x64 RGBA8 texture .*" + REFUSAL):
        texel.Texture(a, max_memory=10_000)
    t = texel.Texture(a)
    uv = np.zeros((100, 2), np.float32)
    with pytest.raises(MemoryError, match=r"the samples \(400 values of float32\) " + REFUSAL):
        t.sample(uv, filter="nearest", max_memory=1000)
    # A float64 array's float32 copy is charged too.
    with pytest.raises(MemoryError, match=r"uv as float32 \(200 values\) " + REFUSAL):
        t.sample(uv.astype(np.float64), filter="nearest", max_memory=100)
    with pytest.raises(MemoryError, match=r"the 100 encoded RGBA values " + REFUSAL):
        texel.encode(np.zeros((100, 4), np.float32), max_memory=100)
    with pytest.raises(MemoryError, match=r"the 64x64 warped image " + REFUSAL):
        texel.warp(a, [0, 0, 64, 0, 64, 64, 0, 64], max_memory=10_000)
    with pytest.raises(MemoryError, match="needs about"):
        texel.render("builtin:ground", size=(64, 36), max_memory=1000)
    # Within the limit, the same calls work.
    assert t.sample(uv, filter="nearest", max_memory=1 << 20).shape == (100, 4)


def test_a_structure_that_does_not_fit_is_a_memory_error_not_a_silent_fallback():
    t = texel.Texture(np.zeros((256, 256, 4), np.float32))
    uv = np.full((4, 2), 0.5)
    d = np.full((4, 2), 0.01)
    with pytest.raises(MemoryError, match=r"the summed-area table of the 256x256 texture " + REFUSAL):
        t.sample(uv, d, d, filter="sat", max_memory=1 << 20)
    assert np.array_equal(t.sample(uv, d, d, filter="sat"), np.zeros((4, 4), np.float32))


def _sample_code(k):
    """What a child computes: a texture of code k sampled (linear, so k / 255), and a render."""
    t = texel.Texture(np.full((8, 8, 4), k, np.uint8))
    value = t.sample(np.array([[0.5, 0.5]]), filter="bilinear")[0, 0]
    image = texel.render("builtin:ground", size=(16, 9))
    return float(value), image


def _sample_texture(t):
    return t.sample(np.array([[0.25, 0.75]]), filter="bilinear")


def test_a_forked_pool_maps_texel_calls():
    # The parent's threads are up before the fork.
    _, parent_image = _sample_code(0)
    textures = [texel.Texture(np.full((4, 4, 4), k, np.uint8), color="srgb") for k in (3, 200)]
    with multiprocessing.get_context("fork").Pool(2) as pool:
        # A hang fails here instead of hanging the suite.
        got = pool.map_async(_sample_code, range(4)).get(timeout=120)
        # Textures cross to the children pickled.
        sampled = pool.map_async(_sample_texture, textures).get(timeout=120)
    for k, (value, image) in enumerate(got):
        assert value == np.float32(k) / np.float32(255)
        np.testing.assert_array_equal(image, parent_image)
    for t, s in zip(textures, sampled):
        np.testing.assert_array_equal(s, _sample_texture(t))


def test_os_fork_children_run_texel_calls():
    expected, image = _sample_code(7)
    pid = os.fork()
    if pid == 0:
        try:
            value, child_image = _sample_code(7)
            os._exit(0 if value == expected and np.array_equal(child_image, image) else 1)
        except BaseException:
            os._exit(2)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            break
        time.sleep(0.05)
    else:
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
        pytest.fail("the forked child's texel call did not finish")
    assert os.waitstatus_to_exitcode(status) == 0
