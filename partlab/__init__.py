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

__all__ = ["__version__"]


def __getattr__(name: str):
    """``__version__`` is read from the installed metadata on first use: importing
    :mod:`importlib.metadata` costs more than the rest of ``import partlab``, and ``partlab track``
    never needs it."""
    if name != "__version__":
        raise AttributeError(f"module 'partlab' has no attribute {name!r}")
    from importlib.metadata import PackageNotFoundError, version

    try:
        value = version("partlab")
    except PackageNotFoundError:  # running from a source tree that was never installed
        value = "0.2.0"
    globals()["__version__"] = value
    return value
