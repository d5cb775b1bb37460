"""The setup's warm-up step (wheelrail.warmup) names every item it compiles and never fails the setup."""

import io

import wheelrail.warmup as warmup


def test_warm_up_reports_progress_and_survives_a_failing_scene(monkeypatch):
    import rigid_dynamics.wheelset as wheelset

    calls = []

    def fake_simulate(scene):
        calls.append(scene.duration_s)
        raise ValueError("boom")

    monkeypatch.setattr(wheelset, "simulate", fake_simulate)
    monkeypatch.setattr("wheelrail.cases.warm_up", lambda method, material: 0.0)

    def fake_wheelset_search():
        raise RuntimeError("bang")

    monkeypatch.setattr(warmup, "_warm_up_wheelset_search", fake_wheelset_search)
    stream = io.StringIO()
    timings = warmup.warm_up_all(stream)
    text = stream.getvalue()
    assert "compiling the fastsim contact kernels" in text and "compiling the dynamics kernels of scene" in text
    assert "warning: scene" in text and "boom" in text and "numba kernels ready" in text
    assert "compiling the wheelset contact search kernels" in text and "warning: wheelset search" in text
    assert "bang" in text and "wheelset search" in timings
    assert calls and all(d < 0.01 for d in calls)  # two steps per scene, not the scene's duration
    assert any(key.startswith("scene ") for key in timings)
