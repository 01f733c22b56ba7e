"""partlab: label human body parts in video from a browser.

Particle-filter trackers propose boxes for each person's head, torso and hip-leg (Zhao & Lee)
and for heads and hands (*3D tracking of the hands and head of interacting people from several
cameras*; Xu, Deng & Jia); the user corrects them in a Streamlit app; partlab retrains its
failure detectors and variance parameters from the corrections and exports datasets.

Sub-packages: :mod:`partlab.tracking` (pure computation: shared machinery and one sub-package
per tracker), :mod:`partlab.models` (failure SVMs, variance parameters, bundles),
:mod:`partlab.labelling` (store, takes, formats, evaluation, synthetic scenes) and
:mod:`partlab.app` (the Streamlit pages). Importing ``partlab`` loads none of them.
"""

from importlib.metadata import PackageNotFoundError
from importlib.metadata import version as _version

try:
    __version__ = _version("partlab")
except PackageNotFoundError:  # running from a source tree that was never installed
    __version__ = "0.2.0"

__all__ = ["__version__"]
