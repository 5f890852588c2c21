"""The ``whitted`` family: pixel coverage (W-SS; lightquad's
src/whitted/). Everything the harness knows about it.

Mitsuba computes ``coverage``, the fraction of ``scene.pixel`` that the
scene's one triangle covers, as the pixel value of a render in which the
triangle is a flat emitter of radiance 1 against a black background:

* the camera is Mitsuba's ``perspective`` sensor with lightquad's eye,
  look-at point, up vector and vertical field of view (``fov_axis`` y), on a
  film of the file's width and height cropped to the one pixel, with the
  ``box`` reconstruction filter: a pixel's value is the mean of its samples,
  each 1 where the camera ray meets the triangle and 0 elsewhere, so its
  expectation is the covered fraction of the pixel square;
* the triangle is a one-face OBJ with an ``area`` emitter, wound to face the
  eye (an area light emits from its front only), and the ``path``
  integrator with ``max_depth`` 1 sees emitters only where camera rays meet
  them;
* float32: Mitsuba rounds the corners and the camera to float32, which moves
  the edges by about 1e-7 of their distance; ``float32_error`` bounds the
  fraction's change by that times the triangle's perimeter in pixels.

Not expressible: scenes of more than one object or of an object other than
a triangle (their footprint is not a single emitter's), and the ``pixel``
and ``image`` quantities (lightquad's shading, not coverage).
"""

import os
import tempfile

import numpy as np

from ..mitsuba3 import mean_of_renders, require_mitsuba
from ..spec import SpecError, number, unit, vec3

QUANTITIES = ("coverage", "pixel", "image")


class Scene:
    def __init__(self, eye, look_at, up, fov_y, width, height, corners, pixel):
        self.eye = eye
        self.look_at = look_at
        self.up = up
        self.fov_y = fov_y
        self.width = width
        self.height = height
        self.corners = corners
        self.pixel = pixel


def _whole(value, path, lo, hi):
    if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
        raise SpecError(path, f"expected a whole number in [{lo}, {hi}], got {value!r}")
    return value


def read_scene(scene) -> Scene:
    """The ``scene`` object of a whitted experiment file: its camera, its
    ``pixel`` (or None) and the corners of its triangle when it is the one
    object (else None; shading fields are lightquad's alone)."""
    if not isinstance(scene, dict):
        raise SpecError("scene", f"expected an object, got {scene!r}")
    cam = scene.get("camera")
    if not isinstance(cam, dict):
        raise SpecError("scene.camera", f"expected an object, got {cam!r}")
    eye = np.asarray(vec3(cam.get("eye"), "scene.camera.eye"))
    look_at = np.asarray(vec3(cam.get("look_at"), "scene.camera.look_at"))
    unit(tuple(look_at - eye), "scene.camera.look_at")
    up = np.asarray(unit(vec3(cam.get("up"), "scene.camera.up"), "scene.camera.up"))
    if not np.linalg.norm(np.cross(up, look_at - eye)) > 0.0:
        raise SpecError("scene.camera.up", "expected a direction not parallel to the view")
    fov_y = number(cam.get("fov_y"), "scene.camera.fov_y", 1e-3, 179.0)
    width = _whole(cam.get("width"), "scene.camera.width", 1, 1 << 16)
    height = _whole(cam.get("height"), "scene.camera.height", 1, 1 << 16)
    objects = scene.get("objects")
    if not isinstance(objects, list):
        raise SpecError("scene.objects", f"expected a list, got {objects!r}")
    corners = None
    if len(objects) == 1 and isinstance(objects[0], dict) and objects[0].get("type") == "triangle":
        tri = objects[0]
        corners = [np.asarray(vec3(tri.get(v), f"scene.objects[0].{v}")) for v in ("a", "b", "c")]
        if not np.linalg.norm(np.cross(corners[1] - corners[0], corners[2] - corners[0])) > 0.0:
            raise SpecError("scene.objects[0]", "a triangle of zero area (collinear corners)")
    pixel = scene.get("pixel")
    if pixel is not None:
        if not isinstance(pixel, list) or len(pixel) != 2:
            raise SpecError("scene.pixel", f"expected [column, row], got {pixel!r}")
        pixel = (_whole(pixel[0], "scene.pixel[0]", 0, width - 1),
                 _whole(pixel[1], "scene.pixel[1]", 0, height - 1))
    return Scene(eye, look_at, up, fov_y, width, height, corners, pixel)


class Settings:
    """Camera rays: full accuracy (2^28 in 4096 renders, about 80 s; standard
    error 2.7e-5 for a pixel 70% covered) or ``quick`` for a smoke run."""

    def __init__(self, quick: bool = False):
        self.quick = quick
        self.passes = 16 if quick else 4096
        self.spp = 1 << 16

    def as_dict(self):
        return {"mode": "quick" if self.quick else "full", "passes": self.passes,
                "spp_per_pass": self.spp}


def require_expressible(exp):
    """A SpecError at ``scene.objects`` unless the scene is one triangle (the
    one emitter whose coverage Mitsuba renders here)."""
    if exp.scene.corners is None:
        raise SpecError("scene.objects", "expected one object, a triangle: the coverage "
                                         "cross-check renders one flat emitter (lightquad's "
                                         "shading of other scenes is not cross-checked)")


def unsupported_reason(exp, quantity):
    if quantity != "coverage":
        return "only coverage is cross-checked (pixel and image are lightquad's shading)"
    if exp.scene.pixel is None:
        return "the scene gives no `pixel`"
    return None


def build_scene(exp, tmp, crop=True, spp=1 << 16):
    """The Mitsuba scene: the triangle as a flat emitter facing the eye, the
    camera on a film cropped to ``scene.pixel`` (or whole)."""
    mi, _ = require_mitsuba()
    s = exp.scene
    a, b, c = s.corners
    # Mitsuba's face normal is (b - a) x (c - a); its emitter lights that side.
    if np.dot(np.cross(b - a, c - a), s.eye - a) < 0.0:
        b, c = c, b
    fd, obj = tempfile.mkstemp(suffix=".obj", dir=tmp)
    with os.fdopen(fd, "w") as f:
        for v in (a, b, c):
            f.write("v {:.17g} {:.17g} {:.17g}\n".format(*v))
        f.write("f 1 2 3\n")
    film = {"type": "hdrfilm", "width": s.width, "height": s.height,
            "rfilter": {"type": "box"}, "pixel_format": "rgb", "component_format": "float32"}
    if crop:
        film.update({"crop_offset_x": s.pixel[0], "crop_offset_y": s.pixel[1],
                     "crop_width": 1, "crop_height": 1})
    to_world = mi.ScalarTransform4f().look_at(origin=s.eye.tolist(), target=s.look_at.tolist(),
                                              up=s.up.tolist())
    return mi.load_dict({
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 1},
        "triangle": {"type": "obj", "filename": obj, "face_normals": True,
                     "emitter": {"type": "area", "radiance": 1.0},
                     "bsdf": {"type": "diffuse", "reflectance": 0.0}},
        "sensor": {"type": "perspective", "fov": s.fov_y, "fov_axis": "y",
                   "to_world": to_world, "film": film,
                   "sampler": {"type": "independent", "sample_count": spp}},
    })


def perimeter_in_pixels(s):
    """The projected triangle's perimeter in pixels (for the float32 bound)."""
    forward = (s.look_at - s.eye) / np.linalg.norm(s.look_at - s.eye)
    right = np.cross(forward, s.up)
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    scale = s.height / (2.0 * np.tan(np.radians(s.fov_y) / 2.0))
    pts = []
    for p in s.corners:
        v = p - s.eye
        z = np.dot(v, forward)
        pts.append(np.array([np.dot(v, right) / z, np.dot(v, up) / z]) * scale)
    return sum(np.linalg.norm(pts[i] - pts[(i + 1) % 3]) for i in range(3))


def compute(exp, quantity, settings):
    with tempfile.TemporaryDirectory() as tmp:
        scene = build_scene(exp, tmp, spp=settings.spp)
        value, std_error = mean_of_renders(scene, settings.passes, settings.spp, exp.seed)
    s = exp.scene
    return {
        "value": value,
        "std_error": std_error,
        "samples": settings.passes * settings.spp,
        "float32_error": 1e-6 * perimeter_in_pixels(s),
        "method": f"Mitsuba perspective sensor (fov_y {s.fov_y}, {s.width} x {s.height} film "
                  f"cropped to pixel {list(s.pixel)}, box filter) over the triangle as a flat "
                  f"area emitter of radiance 1 facing the eye, path integrator max_depth 1; "
                  f"float64 mean of {settings.passes} renders of {settings.spp} samples, "
                  f"standard error over renders",
    }
