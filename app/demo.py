"""Make the built-in demo clip if it is not there yet (``make run`` calls this)."""

from __future__ import annotations

from labelling.config import data_dir


def ensure_demo() -> None:
    demo = data_dir() / "demo"
    try:
        from labelling.synth import render_scenario
    except ImportError:  # the generator has not landed yet
        return
    target = demo / "single"
    if not (target / "clip.mp4").exists():
        print(f"partlab: rendering the demo clip into {target}", flush=True)
        render_scenario("single", target, seed=0)


if __name__ == "__main__":
    ensure_demo()
