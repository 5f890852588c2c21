"""The equation families the harness knows, by the ``family`` tag of an
experiment file; this registry is the only place that names them.

A family module provides

* ``QUANTITIES``: the quantity names its experiment files may ask for;
* ``Settings(quick)``: its sample counts, full or for a smoke run, with
  ``as_dict()`` for the values file;
* ``read_scene(scene)``: its reading of the file's ``scene`` object (SpecError
  with the JSON path for a fault);
* ``require_expressible(exp)``: a SpecError naming the JSON path if Mitsuba 3
  cannot express the scene at all;
* ``unsupported_reason(exp, quantity)``: why a quantity is not computed, or
  None;
* ``compute(exp, quantity, settings)``: the quantity's value as a dict with
  ``value``, ``std_error``, ``samples``, ``method`` and details.
"""

from . import exchange, furnace, rendering, volume, whitted

FAMILIES = {"volume": volume, "rendering": rendering, "furnace": furnace, "whitted": whitted,
            "exchange": exchange}
