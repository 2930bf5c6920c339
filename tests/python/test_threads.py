"""Concurrency: Python threads render at once (the GIL is released), each with its own
Renderer; one Renderer shared by threads serializes their calls. Images equal the
single-threaded ones."""
import gc
import threading

import numpy as np
import pytest

import abcube
from conftest import assert_same_image, small_scene_dict

VIEWS = [
    {"position": [0, 2.2, 6]},
    {"position": [4, 2.5, 4]},
    {"position": [-4, 1.5, 4.5]},
    {"position": [0, 4, 5], "fov_y": 40},
]


def run_threads(target, count):
    errors = []

    def guarded(k):
        try:
            target(k)
        except BaseException as e:  # reported in the main thread
            errors.append(e)
    threads = [threading.Thread(target=guarded, args=(k,)) for k in range(count)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=300)
    assert not any(t.is_alive() for t in threads), "a render thread hung"
    if errors:
        raise errors[0]


@pytest.mark.parametrize("method", ["abuffer", "raytrace"])
def test_four_threads_own_renderers(scene, method):
    # The reference: each view rendered alone, in this thread.
    expected = [abcube.Renderer(gl="none").render(scene, method=method, camera=v) for v in VIEWS]
    assert len({e.tobytes() for e in expected}) == len(VIEWS), "the views must differ"

    # Each thread renders every view three times with its own Renderer, one scene shared.
    results = [[] for _ in VIEWS]
    start = threading.Barrier(len(VIEWS))

    def work(k):
        renderer = abcube.Renderer(gl="none", threads=1)
        start.wait()
        for round_ in range(3):
            for j in range(len(VIEWS)):
                view = (k + j) % len(VIEWS)
                results[k].append((view, renderer.render(scene, method=method, camera=VIEWS[view])))
    run_threads(work, len(VIEWS))
    for k, images in enumerate(results):
        assert len(images) == 3 * len(VIEWS)
        for view, image in images:
            assert_same_image(image, expected[view], f"threads_{method}_{k}_{view}")


def test_threads_share_one_renderer(scene):
    # Calls on one Renderer are serialized, not broken.
    renderer = abcube.Renderer(gl="none")
    expected = [renderer.render(scene, method="abuffer", camera=v) for v in VIEWS]
    results = {}

    def work(k):
        results[k] = renderer.render(scene, method="abuffer", camera=VIEWS[k])
    run_threads(work, len(VIEWS))
    for k in range(len(VIEWS)):
        assert_same_image(results[k], expected[k], f"shared_renderer_{k}")
    assert renderer.renders == 2 * len(VIEWS)


def test_gil_released_during_render(scene):
    # While one thread renders a big image, this thread keeps running Python code.
    big = abcube.scene_from_dict(small_scene_dict(256, 192, 128))
    done = threading.Event()
    ticks = 0

    def work(_):
        abcube.Renderer(gl="none", threads=1).render(big, method="abuffer")
        done.set()
    thread = threading.Thread(target=work, args=(0,))
    thread.start()
    while not done.is_set():
        ticks += 1
        done.wait(0.001)
    thread.join()
    # Held, the GIL would let this loop run once or twice in all.
    assert ticks > 5, ticks


def test_gl_renderer_bound_to_its_thread(scene):
    # A Renderer that opened GL on one thread refuses (RuntimeError) a call from another.
    renderer = abcube.Renderer(gl="egl")
    first = renderer.render(scene, method="gpu")
    errors = []

    def other(_):
        try:
            renderer.render(scene, method="gpu")
        except RuntimeError as e:
            errors.append(e)
    thread = threading.Thread(target=other, args=(0,))
    thread.start()
    thread.join()
    assert len(errors) == 1 and not isinstance(errors[0], ValueError)
    assert np.array_equal(renderer.render(scene, method="gpu"), first)


def test_gl_renderer_freed_off_its_thread(scene):
    # A Renderer whose GL context was opened by a thread that has ended is freed by another
    # thread (the garbage collector's) without a crash.
    holder = {}

    def work(_):
        renderer = abcube.Renderer(gl="egl")
        holder["image"] = renderer.render(scene, method="gpu")
        holder["renderer"] = renderer
    run_threads(work, 1)
    assert holder["renderer"].gl_path.startswith("egl")
    del holder["renderer"]
    gc.collect()
    # GL still works here afterwards, and renders the same image.
    assert np.array_equal(abcube.Renderer(gl="egl").render(scene, method="gpu"), holder["image"])
