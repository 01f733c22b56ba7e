"""What `partlab track` loads (issue 12: start-up). A 5-frame track spends most of its time
importing; these are packages the command line and the tracking path must not pay for (numba's
compiler is set up without scipy's BLAS and cffi: ``partlab.tracking.core.kernels.prepare``)."""

import subprocess
import sys

import pytest

HEAVY = ("sqlalchemy", "alembic", "scipy.optimize", "scipy.linalg", "cffi", "streamlit", "distributed", "sklearn",
         "plotly")


@pytest.fixture(scope="module")
def clip(tmp_path_factory):
    out = tmp_path_factory.mktemp("start")
    subprocess.run([sys.executable, "-m", "partlab", "synth", str(out), "--frames", "5", "--seed", "1"], check=True,
                   capture_output=True)
    return out / "clip.mp4"


@pytest.mark.parametrize("tracker, init", [("body", False), ("body", True), ("limbs", False), ("all", False)])
def test_a_short_track_loads_no_store_scipy_or_app(clip, tracker, init, tmp_path):
    out = tmp_path / "tracks.csv"
    extra = ["--init", str(clip.parent / "init.csv")] if init else []  # tracks started: detections are assigned
    heavy = HEAVY + (("pandas",) if tracker == "body" else ())  # the body path reads and writes rows without it
    code = ("import sys\n"
            "from partlab.cli import main\n"
            f"assert main(['track', {str(clip)!r}, '--tracker', {tracker!r}, '-o', {str(out)!r}, *{extra!r}]) == 0\n"
            f"print('loaded:', *(m for m in {heavy!r} if m in sys.modules))\n")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.is_file()
    assert run.stdout.splitlines()[-1].split() == ["loaded:"]
