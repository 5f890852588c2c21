"""Reading a lightquad experiment file (the format of /README.md and
src/experiment/spec.rs): the fields every family shares, and the ``family``
tag that picks the module (lqref/families/) reading the family's ``scene``
and knowing its quantities.

This is not a validator: ``lightquad check FILE`` is. Only what the harness
uses is read and checked here, with the JSON path in every error.
"""

import json
import math
from dataclasses import dataclass


class SpecError(ValueError):
    """A fault in an experiment file, or a scene element Mitsuba cannot express;
    the message names the JSON path."""

    def __init__(self, path: str, message: str):
        super().__init__(f"at `{path}`: {message}")
        self.path = path


@dataclass
class Experiment:
    name: str
    path: str
    family: str  # the `family` tag: a key of families.FAMILIES
    scene: object  # the family module's reading of `scene`
    quantities: list  # names from the family's QUANTITIES
    seed: int


def load(path) -> Experiment:
    """Reads the experiment file at ``path``; its family reads the ``scene``."""
    # Imported here, not above: the families need numpy, and --check needs only
    # the standard library.
    from .families import FAMILIES

    with open(path, "rb") as f:
        raw = json.loads(f.read().decode("utf-8"))
    return from_dict(raw, str(path))


def from_dict(raw, path) -> Experiment:
    """An experiment from its parsed JSON ``raw`` (``path`` names where it came
    from); its family reads the ``scene``."""
    from .families import FAMILIES

    if not isinstance(raw, dict):
        raise SpecError(".", "an experiment file is a JSON object")
    tag = raw.get("family")
    if not isinstance(tag, str) or tag not in FAMILIES:
        problem = "missing field" if tag is None else f"unknown family {tag!r}"
        raise SpecError("family", f"{problem}; accepted families: {', '.join(FAMILIES)}")
    family = FAMILIES[tag]
    for key in ("name", "scene", "quantities"):
        if key not in raw:
            raise SpecError(key, "missing field")
    scene = family.read_scene(raw["scene"])

    if not isinstance(raw["quantities"], list):
        raise SpecError("quantities", f"expected a list, got {raw['quantities']!r}")
    quantities = list(raw["quantities"])
    for i, q in enumerate(quantities):
        if q not in family.QUANTITIES:
            raise SpecError(f"quantities[{i}]",
                            f"unknown quantity {q!r}; known: {family.QUANTITIES}")

    name = raw["name"]
    if not isinstance(name, str) or not name or "/" in name or "\\" in name \
            or name.startswith("."):
        raise SpecError("name", f"{name!r}: expected a file name (no '/', '\\' or leading "
                                "'.'): the values file is <out>/<name>.json")
    seed = raw.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise SpecError("seed", f"expected a whole number >= 0, got {seed!r}")
    return Experiment(
        name=name,
        path=str(path),
        family=tag,
        scene=scene,
        quantities=quantities,
        seed=seed,
    )


# ----------------------------------------------------------------------------
# Helpers for the families' scene readers


def vec3(value, path):
    """``value`` as three floats; a SpecError at ``path`` unless it is three
    finite numbers."""
    if not (isinstance(value, list) and len(value) == 3 and all(_is_num(x) for x in value)):
        raise SpecError(path, f"expected three numbers, got {value!r}")
    return tuple(float(x) for x in value)


def unit(v, path):
    """``v`` normalised; a SpecError at ``path`` for a zero vector."""
    n = math.sqrt(sum(x * x for x in v))
    if not n > 0.0:
        raise SpecError(path, f"expected a non-zero vector, got {list(v)}")
    return tuple(x / n for x in v)


def number(value, path, lo=-math.inf, hi=math.inf):
    """``value`` as a float in ``[lo, hi]``; a SpecError at ``path`` otherwise
    (booleans, strings, None, NaN and infinities included)."""
    if not (_is_num(value) and lo <= value <= hi):
        raise SpecError(path, f"expected a number in [{lo:g}, {hi:g}], got {value!r}")
    return float(value)


def _is_num(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)
