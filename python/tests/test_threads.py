"""Long calls release the GIL, report progress, and stop on Ctrl+C or when asked."""

import _thread
import signal
import threading
import time

import numpy as np
import pytest

import fairmesh


@pytest.fixture(scope="module")
def noisy(bunny):
    return fairmesh.noise(bunny.vertices, bunny.faces, sigma=0.3, seed=1)


def test_python_threads_run_while_fair_works(bunny, noisy):
    counted = []
    stop = threading.Event()

    def count():
        n = 0
        while not stop.is_set():
            n += 1
            if n % 1000 == 0:
                counted.append(time.perf_counter())

    worker = threading.Thread(target=count)
    worker.start()
    try:
        time.sleep(0.05)
        started = time.perf_counter()
        fairmesh.fair(noisy, bunny.faces, rounds=30)
        ended = time.perf_counter()
    finally:
        stop.set()
        worker.join()
    during = [t for t in counted if started < t < ended]
    # Held, the GIL would let the counter run only before and after the call.
    assert ended - started > 0.1
    assert len(during) > 10, f"{len(during)} counts in {ended - started:.2f} s"


def test_two_fairings_from_two_threads_run_at_the_same_time(bunny, noisy):
    # Each call's report times its fairing; the fairings of two threads overlap in time only if
    # neither holds the GIL while it works (held, the second could not start before the first
    # returned). This holds however busy the machine is.
    spans = []

    def one():
        _, report = fairmesh.fair(noisy, bunny.faces, rounds=15, threads=1)
        ended = time.perf_counter()
        spans.append((ended - report["time_ms"] / 1e3, ended))

    threads = [threading.Thread(target=one) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    (start_a, end_a), (start_b, end_b) = spans
    overlap = min(end_a, end_b) - max(start_a, start_b)
    shorter = min(end_a - start_a, end_b - start_b)
    assert overlap > 0.5 * shorter, f"fairings {spans} overlap by {overlap:.3f} s"


def test_progress_is_reported_and_can_cancel(bunny, noisy):
    fractions = []
    fairmesh.hierarchy(noisy, bunny.faces, progress=fractions.append)
    assert fractions and fractions[-1] == 1.0
    assert fractions == sorted(fractions)
    with pytest.raises(fairmesh.Cancelled):
        fairmesh.hierarchy(noisy, bunny.faces, progress=lambda fraction: False)
    levels = fairmesh.hierarchy(noisy, bunny.faces)
    with pytest.raises(ZeroDivisionError):
        levels.multires(10, progress=lambda fraction: 1 / 0)
    # The object stays usable after a cancelled run.
    first = levels.multires(10)
    np.testing.assert_array_equal(first, levels.multires(10))


def test_fair_reports_every_round_and_stops_when_told(bunny, noisy):
    fractions = []
    fairmesh.fair(noisy, bunny.faces, rounds=29, progress=fractions.append)
    # After every round, however fast the rounds come: rounds done / rounds asked for.
    assert fractions == [float(np.float32(done / 29)) for done in range(1, 30)]
    automatic = []
    _, report = fairmesh.fair(noisy, bunny.faces, progress=automatic.append)
    # The automatic strength: one report a round run (the error estimated after each), then
    # 1.0 once the best round is kept.
    assert len(automatic) == len(report["risk_by_round"]) + 1
    assert automatic[-1] == 1.0 and automatic == sorted(set(automatic))
    heard = []

    def stop_soon(fraction):
        heard.append(fraction)
        return fraction < 0.05

    with pytest.raises(fairmesh.Cancelled):
        fairmesh.fair(noisy, bunny.faces, rounds=2000, progress=stop_soon)
    assert heard[-1] >= 0.05 and heard[-1] < 0.5


def test_ctrl_c_stops_a_long_fair(bunny, noisy):
    # A process started in the background (`cmd &`, some CI runners) inherits SIGINT ignored, and
    # Python then ignores Ctrl+C and `interrupt_main` alike; the test needs Python's own handler.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        _ctrl_c_stops_a_long_fair(bunny, noisy)
    finally:
        signal.signal(signal.SIGINT, previous)


def _ctrl_c_stops_a_long_fair(bunny, noisy):
    quick = time.perf_counter()
    fairmesh.fair(noisy, bunny.faces, rounds=20)
    per_round = (time.perf_counter() - quick) / 20
    timer = threading.Timer(0.3, _thread.interrupt_main)
    timer.start()
    started = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        fairmesh.fair(noisy, bunny.faces, rounds=2000)
    stopped = time.perf_counter() - started
    timer.join()
    # 2000 rounds would take about 2000 * per_round; it stops soon after 0.3 s, long before. (A
    # ratio of two times taken on the same machine, with a margin wide enough for its drift.)
    assert stopped < 0.25 * 2000 * per_round, f"{stopped:.2f} s ({per_round:.4f} s a round)"


def test_a_call_in_a_worker_thread_stops_when_the_main_thread_asks(bunny, noisy):
    # Python gives Ctrl+C to the main thread only; the documented way to stop a call in another
    # thread is a progress callback that reads an event the main thread sets.
    stop = threading.Event()
    started = threading.Event()
    heard = []
    outcome = []

    def keep_going(fraction):
        heard.append(fraction)
        started.set()
        return not stop.is_set()

    def work():
        try:
            fairmesh.fair(noisy, bunny.faces, rounds=2000, progress=keep_going)
            outcome.append("finished")
        except fairmesh.Cancelled as cancelled:
            outcome.append(cancelled)

    worker = threading.Thread(target=work)
    worker.start()
    started.wait()
    stop.set()  # what the main thread does on KeyboardInterrupt
    worker.join()
    assert isinstance(outcome[0], fairmesh.Cancelled)
    assert heard[-1] < 0.5, f"{len(heard)} rounds ran"
