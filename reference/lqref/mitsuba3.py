"""Mitsuba 3 for every family: importing it (variant ``scalar_rgb``), the
versions a values file records, and points and vectors from Python sequences.

Every Mitsuba variant computes in float32; this one is ``scalar_rgb`` (CPU, no
LLVM or CUDA). How a family's scene becomes a Mitsuba scene is in its module
under ``lqref/families/``.
"""

import sys

VARIANT = "scalar_rgb"
_MI = None


class MitsubaMissing(RuntimeError):
    """Mitsuba 3 (or the variant) is not available in this Python."""


def use_llvm_if_present():
    """Selects ``llvm_ad_rgb`` instead of ``scalar_rgb`` for what follows when
    Dr.Jit is told where libLLVM is (``DRJIT_LIBLLVM_PATH`` naming a file) and
    the build has the variant; returns the variant in use. The values files
    are computed in ``scalar_rgb``; the server (lqref.serve) takes the faster
    one."""
    global VARIANT
    import os

    path = os.environ.get("DRJIT_LIBLLVM_PATH", "")
    if _MI is None and path and os.path.isfile(path):
        try:
            import mitsuba as mi
        except ImportError:
            return VARIANT
        if "llvm_ad_rgb" in mi.variants():
            VARIANT = "llvm_ad_rgb"
    return VARIANT


def require_mitsuba():
    """Imports Mitsuba 3 and Dr.Jit and selects ``VARIANT`` (``scalar_rgb``
    unless use_llvm_if_present chose LLVM); returns ``(mi, dr)``.

    Raises MitsubaMissing with the install command when they are absent."""
    global _MI
    if _MI is not None:
        return _MI
    try:
        import drjit as dr
        import mitsuba as mi
    except ImportError as e:
        raise MitsubaMissing(
            f"Mitsuba 3 is not installed for {sys.executable} ({e}).\n"
            "Install the pinned versions with:\n"
            "    pip install -r reference/requirements.txt"
        ) from e
    if VARIANT not in mi.variants():
        raise MitsubaMissing(
            f"this Mitsuba build has no `{VARIANT}` variant (it has {mi.variants()}); "
            "install the pinned wheel: pip install -r reference/requirements.txt"
        )
    mi.set_variant(VARIANT)
    _MI = (mi, dr)
    return _MI


def versions():
    """The variant and the Mitsuba and Dr.Jit versions, as a values file records them."""
    mi, dr = require_mitsuba()
    return {"mitsuba_variant": VARIANT, "mitsuba_version": mi.__version__,
            "drjit_version": dr.__version__}


def point(p):
    """``p`` (three numbers) as a Mitsuba ``Point3f``."""
    mi, _ = require_mitsuba()
    return mi.Point3f(float(p[0]), float(p[1]), float(p[2]))


def vector(v):
    """``v`` (three numbers) as a Mitsuba ``Vector3f``."""
    mi, _ = require_mitsuba()
    return mi.Vector3f(float(v[0]), float(v[1]), float(v[2]))


def mean_of_renders(scene, passes, spp, seed):
    """The float64 mean of ``passes`` renders of ``spp`` samples each of a
    scene with a 1x1 film (its RGB averaged), and the standard error over the
    renders: one film accumulating far more samples drifts in float32. The
    renders' seeds follow from ``seed``, so a rerun reproduces the value."""
    mi, _ = require_mitsuba()
    import numpy as np

    values = np.empty(passes)
    base = (seed * 1_000_003) % 2 ** 32
    for k in range(passes):
        img = np.asarray(mi.render(scene, spp=spp, seed=(base + k) % 2 ** 32), dtype=np.float64)
        values[k] = float(np.mean(img[0, 0, :3]))
    return float(np.mean(values)), float(np.std(values, ddof=1) / np.sqrt(values.size))
