"""Tests of the Mitsuba 3 reference harness, each against an independent value:
hand-computed hashes, lightquad's voxel-grid formula in float64 NumPy, and the
closed forms of lightquad::exact::volume (restated here)."""

import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from lqref import fnv1a64, file_hash
from lqref import mitsuba3, runner, spec
from lqref.__main__ import main
from lqref.families import FAMILIES, exchange, furnace, rendering, volume, whitted

REPO = Path(__file__).resolve().parents[2]
LIGHTQUAD = REPO / "target" / "release" / "lightquad"


def write_experiment(tmp_path, name, scene, quantities, reference=None, family="volume"):
    """A volume experiment file (``family=None``: without the tag)."""
    doc = {
        "name": name,
        **({} if family is None else {"family": family}),
        "description": "test",
        "equations": ["V-tau"],
        "scene": scene,
        "quantities": quantities,
        "rules": [{"rule": "gauss-legendre"}],
        "budgets": [4],
        "reference": reference or {"type": "closed-form"},
    }
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(doc, indent=2))
    return path


def settings(passes=None, walks=None):
    s = volume.Settings(quick=True)
    if passes is not None:
        s.passes = passes
    if walks is not None:
        s.walks = walks
    return s


# ---------------------------------------------------------------- hash


def test_fnv1a64_known_values():
    assert fnv1a64(b"") == "cbf29ce484222325"  # the offset basis itself
    # b"a" by hand: one xor, one multiply, modulo 2^64.
    by_hand = ((0xCBF29CE484222325 ^ 0x61) * 0x100000001B3) % 2 ** 64
    assert fnv1a64(b"a") == f"{by_hand:016x}" == "af63dc4c8601ec8c"
    assert fnv1a64(b"foobar") == "85944171f73967e8"  # published FNV-1a test vector


@pytest.mark.skipif(not LIGHTQUAD.exists(), reason="lightquad not built (cargo build --release)")
def test_file_hash_matches_lightquad():
    path = REPO / "experiments" / "v-l-single-scattering.json"
    out = subprocess.run([str(LIGHTQUAD), "check", str(path)], capture_output=True,
                         text=True, check=True).stdout
    assert f"hash {file_hash(path)}" in out


# ---------------------------------------------------------------- voxel grid


def lightquad_voxel_density(medium, p):
    """src/volume/voxel_grid.rs in float64: values at voxel centres, [z][y][x],
    trilinear, indices clamped, 0 outside the box."""
    lo, hi = np.asarray(medium["min"], float), np.asarray(medium["max"], float)
    n = np.asarray(medium["resolution"])
    data = np.asarray(medium["data"], float).reshape(n[2], n[1], n[0])
    u = (p - lo) / ((hi - lo) / n) - 0.5
    f = np.floor(u)
    w = u - f
    lower = np.clip(f, 0, n - 1).astype(int)
    upper = np.clip(f + 1, 0, n - 1).astype(int)
    out = np.zeros(len(p))
    for a in (0, 1):
        for b in (0, 1):
            for c in (0, 1):
                ix = upper[:, 0] if a else lower[:, 0]
                iy = upper[:, 1] if b else lower[:, 1]
                iz = upper[:, 2] if c else lower[:, 2]
                weight = ((w[:, 0] if a else 1 - w[:, 0]) * (w[:, 1] if b else 1 - w[:, 1])
                          * (w[:, 2] if c else 1 - w[:, 2]))
                out += weight * data[iz, iy, ix]
    inside = np.all((p >= lo) & (p <= hi), axis=1)
    return np.where(inside, out, 0.0)


def box_chord(o, d, lo, hi):
    """The slab method (no axis parallel to the ray here)."""
    ta, tb = (np.asarray(lo) - o) / d, (np.asarray(hi) - o) / d
    return max(np.minimum(ta, tb).max(), 0.0), np.maximum(ta, tb).min()


def distinct_grid():
    nx, ny, nz = 3, 4, 5
    data = [1.0 + x + 10.0 * y + 100.0 * z + 0.25 * ((x * 7 + y * 3 + z) % 5)
            for z in range(nz) for y in range(ny) for x in range(nx)]
    return {"type": "voxel-grid", "min": [-1.0, 0.5, -2.0], "max": [2.0, 1.5, 0.5],
            "resolution": [nx, ny, nz], "data": data}


def test_grid_export_round_trip_at_voxel_centres():
    mi, dr = mitsuba3.require_mitsuba()
    grid = distinct_grid()
    assert len(set(grid["data"])) == len(grid["data"])
    vol = volume.gridvolume(grid)
    nx, ny, nz = grid["resolution"]
    lo, hi = np.array(grid["min"]), np.array(grid["max"])
    it = dr.zeros(mi.Interaction3f)
    for z in range(nz):
        for y in range(ny):
            for x in range(nx):
                centre = lo + (np.array([x, y, z]) + 0.5) / np.array([nx, ny, nz]) * (hi - lo)
                it.p = mitsuba3.point(centre)
                expected = grid["data"][(z * ny + y) * nx + x]
                assert vol.eval_1(it) == pytest.approx(expected, rel=2e-6), (x, y, z)


def test_grid_export_matches_lightquad_trilinear_everywhere(tmp_path):
    grid = distinct_grid()
    path = write_experiment(tmp_path, "grid", {
        "ray": {"origin": [-3.0, 1.0, 0.0], "direction": [1.0, 0.0, 0.0]},
        "medium": grid, "lambda": 1.7}, ["tau"])
    exp = spec.load(path)
    _, medium = volume.build_scene(exp)
    rng = np.random.default_rng(5)
    lo, hi = np.array(grid["min"]), np.array(grid["max"])
    pts = lo + rng.random((2000, 3)) * (hi - lo)  # includes the clamped half-voxel margins
    pts = pts.astype(np.float32).astype(np.float64)  # the points Mitsuba sees
    expected = 1.7 * lightquad_voxel_density(grid, pts)
    assert np.allclose(volume.sigma_t_at(medium, pts), expected, rtol=2e-6, atol=0)


def test_voxel_tau_ratio_tracking_and_ray_march(tmp_path):
    grid = distinct_grid()
    grid["data"] = [v / 1000.0 for v in grid["data"]]  # optical depth about 1
    path = write_experiment(tmp_path, "voxel-tau", {
        "ray": {"origin": [-2.0, 0.7, -1.9], "direction": [1.0, 0.1, 0.7]},
        "medium": grid, "lambda": 1.5}, ["tau"], {"type": "converged", "n": 50})
    exp = spec.load(path)
    res = volume.tau_voxel_grid(exp, settings(walks=2 ** 13))
    # Independent: lightquad's field in float64, fine midpoint rule on the chord.
    o, d = np.array(exp.scene.origin), np.array(exp.scene.direction)
    t_n, t_f = box_chord(o, d, grid["min"], grid["max"])
    assert res["chord"] == pytest.approx([t_n, t_f], abs=1e-6)
    n = 2 ** 20
    ts = t_n + (np.arange(n) + 0.5) * (t_f - t_n) / n
    depth = 1.5 * lightquad_voxel_density(grid, o + ts[:, None] * d).sum() * (t_f - t_n) / n
    tau = math.exp(-depth)
    assert 0.05 < tau < 0.9
    assert abs(res["value"] - tau) <= 4 * res["std_error"]
    assert abs(res["ray_march"]["value"] - tau) <= res["ray_march"]["error_estimate"] + 1e-6 * tau


# ---------------------------------------------------------------- tau, constant sphere


def sphere_chord(o, d, c, r):
    """The closed-form chord of the unit-direction line o + t d through the sphere."""
    o, d, c = (np.asarray(v, float) for v in (o, d, c))
    d = d / np.linalg.norm(d)
    tc = np.dot(c - o, d)
    h2 = np.sum((o + tc * d - c) ** 2)
    half = math.sqrt(max(r * r - h2, 0.0))
    return max(tc - half, 0.0), tc + half


@pytest.mark.parametrize("origin,direction,centre,radius,kappa,lam", [
    ([-3.0, 0.4, 0.1], [1.0, 0.02, 0.0], [0.1, -0.05, 0.0], 1.2, 0.8, 1.25),
    ([-3.0, 0.3, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0], 1.0, 2.620712, 1.0),
    ([0.2, -0.1, 0.3], [0.3, 1.0, -0.2], [0.0, 0.0, 0.0], 1.0, 3.0, 0.5),  # origin inside
    ([5.0, 5.0, 5.0], [-1.0, -1.0, -0.9], [0.0, 0.0, 0.0], 2.0, 0.01, 1.0),  # thin, long
])
def test_tau_constant_sphere_closed_form(tmp_path, origin, direction, centre, radius, kappa, lam):
    path = write_experiment(tmp_path, "sphere", {
        "ray": {"origin": origin, "direction": direction},
        "medium": {"type": "constant-sphere", "centre": centre, "radius": radius,
                   "kappa": kappa}, "lambda": lam}, ["tau"])
    res = volume.tau_constant_sphere(spec.load(path))
    t_n, t_f = sphere_chord(origin, direction, centre, radius)
    depth = lam * kappa * (t_f - t_n)
    exact = math.exp(-depth)
    assert res["value"] == pytest.approx(exact, rel=2e-6 * (1 + depth))
    assert abs(res["value"] - exact) <= res["float32_error"]


def test_tau_stiff_sphere_log_value():
    res = volume.tau_constant_sphere(spec.load(REPO / "experiments" / "v-tau-stiff-sphere.json"))
    assert res["value"] == 0.0
    assert res["log_value"] == pytest.approx(-1e5, rel=1e-6)


def test_tau_ray_missing_the_sphere(tmp_path):
    path = write_experiment(tmp_path, "miss", {
        "ray": {"origin": [-3.0, 2.0, 0.0], "direction": [1.0, 0.0, 0.0]},
        "medium": {"type": "constant-sphere", "centre": [0, 0, 0], "radius": 1.0,
                   "kappa": 1.0}}, ["tau"])
    assert volume.tau_constant_sphere(spec.load(path))["value"] == 1.0


# ---------------------------------------------------------------- I_L, single scattering


def light_behind(sigma, chord, intensity, albedo):
    """lightquad::exact::volume::light_behind with an albedo."""
    return intensity * albedo * sigma / (4 * math.pi) * (-math.expm1(-2 * sigma * chord)) / (2 * sigma)


@pytest.mark.parametrize("kappa,passes", [(1.5, 192), (200.0, 192)])
def test_single_scattering_light_behind_closed_form(tmp_path, kappa, passes):
    """The light straight behind the eye. kappa = 200 would be ~1.8 % low (many
    standard errors) if the camera ray were re-spawned at the boundary or the
    radiancemeter's ray-epsilon offset were left in."""
    origin, direction = [-3.0, 0.2, 0.0], [1.0, 0.0, 0.0]
    path = write_experiment(tmp_path, "ss", {
        "ray": {"origin": origin, "direction": direction},
        "medium": {"type": "constant-sphere", "centre": [0, 0, 0], "radius": 1.0,
                   "kappa": kappa},
        "light": {"toward_light": [-1.0, 0.0, 0.0], "intensity": 2.0, "albedo": 0.8}},
        ["I_L"])
    res = volume.light_single_scattering(spec.load(path), settings(passes=passes))
    t_n, t_f = sphere_chord(origin, direction, [0, 0, 0], 1.0)
    exact = light_behind(kappa, t_f - t_n, 2.0, 0.8)
    float32_floor = 1e-5 * exact
    assert abs(res["value"] - exact) <= 4 * res["std_error"] + float32_floor, \
        (res["value"], exact, res["std_error"])
    assert res["std_error"] < 0.01 * exact


# ---------------------------------------------------------------- families


SPHERE_SCENE = {
    "ray": {"origin": [-3.0, 0.3, 0.0], "direction": [1.0, 0.0, 0.0]},
    "medium": {"type": "constant-sphere", "centre": [0, 0, 0], "radius": 1.0, "kappa": 2.0},
}


def test_every_family_module_has_the_interface():
    assert list(FAMILIES) == ["volume", "rendering", "furnace", "whitted", "exchange"]
    for module in FAMILIES.values():
        assert module.QUANTITIES
        for name in ("Settings", "read_scene", "require_expressible", "unsupported_reason",
                     "compute"):
            assert callable(getattr(module, name)), name


@pytest.mark.parametrize("path", sorted((REPO / "experiments").glob("*.json")),
                         ids=lambda p: p.stem)
def test_every_bundled_experiment_file_reads_or_names_its_family(path):
    """Files of a family the harness knows read; those of lightquad's other
    families (e.g. `calibration`, no scene for Mitsuba) are rejected at `family`."""
    tag = json.loads(path.read_text())["family"]
    if tag in FAMILIES:
        exp = spec.load(path)
        assert exp.family == tag
        assert set(exp.quantities) <= set(FAMILIES[tag].QUANTITIES)
    else:
        with pytest.raises(spec.SpecError, match=f"unknown family '{tag}'") as err:
            spec.load(path)
        assert err.value.path == "family"


def test_unknown_family_is_rejected_with_the_path(tmp_path):
    path = write_experiment(tmp_path, "acoustic", SPHERE_SCENE, ["tau"], family="acoustics")
    with pytest.raises(spec.SpecError) as err:
        spec.load(path)
    assert err.value.path == "family"
    assert "unknown family 'acoustics'" in str(err.value)
    assert "accepted families: volume" in str(err.value)
    assert main([str(path), "--out", str(tmp_path / "v")]) == 2
    assert not (tmp_path / "v" / "acoustic.json").exists()


def test_missing_family_is_rejected(tmp_path):
    path = write_experiment(tmp_path, "untagged", SPHERE_SCENE, ["tau"], family=None)
    with pytest.raises(spec.SpecError, match="accepted families: volume") as err:
        spec.load(path)
    assert err.value.path == "family"
    assert "missing field" in str(err.value)


def test_depth_scheme_and_shadow_in_the_scene_are_accepted(tmp_path):
    """lightquad's numerical choices: read without error, no effect on the values."""
    plain = write_experiment(tmp_path, "plain", SPHERE_SCENE, ["tau"])
    tagged = write_experiment(tmp_path, "tagged", {
        **SPHERE_SCENE, "depth_scheme": "nested", "shadow": "quadrature"}, ["tau"])
    values = [runner.compute(p, quick=True, out_dir=tmp_path / "v", log=lambda *a: None)
              ["quantities"]["tau"]["value"] for p in (plain, tagged)]
    assert values[0] == values[1]


# ---------------------------------------------------------------- files, errors


def test_stale_hash_detection(tmp_path):
    src = REPO / "experiments" / "mitsuba-tau-constant-sphere.json"
    path = tmp_path / "exp.json"
    shutil.copy(src, path)
    out = tmp_path / "values"
    rec = runner.compute(path, quick=True, out_dir=out, log=lambda *a: None)
    assert rec["experiment_hash"] == file_hash(path)
    assert [s for s, *_ in runner.check([path], out)] == ["ok"]
    assert main(["--check", str(path), "--out", str(out)]) == 0

    path.write_bytes(path.read_bytes().replace(b'"kappa": 0.8', b'"kappa": 0.81'))
    assert [s for s, *_ in runner.check([path], out)] == ["stale"]
    assert main(["--check", str(path), "--out", str(out)]) == 1

    (out / "mitsuba-tau-constant-sphere.json").unlink()
    assert [s for s, *_ in runner.check([path], out)] == ["missing"]


def test_values_file_layout_and_unsupported(tmp_path):
    path = write_experiment(tmp_path, "mixed", {
        "ray": {"origin": [-3.0, 0.3, 0.0], "direction": [1.0, 0.0, 0.0]},
        "medium": {"type": "constant-sphere", "centre": [0, 0, 0], "radius": 1.0,
                   "kappa": 2.0},
        "emission": {"type": "constant", "c": 1.0}, "background": 0.5},
        ["tau", "I_E", "I_B", "I"])
    rec = runner.compute(path, quick=True, out_dir=tmp_path / "v", log=lambda *a: None)
    on_disk = json.loads((tmp_path / "v" / "mixed.json").read_text())
    assert on_disk == rec
    for key in ("mitsuba_variant", "mitsuba_version", "run_seconds", "experiment_hash"):
        assert key in rec
    assert rec["mitsuba_variant"] == "scalar_rgb"
    assert set(rec["quantities"]) == {"tau"}
    assert {"value", "std_error", "samples", "method"} <= set(rec["quantities"]["tau"])
    assert set(rec["unsupported"]) == {"I_E", "I_B", "I"}
    assert "emission" in rec["unsupported"]["I_E"]


def test_inexpressible_scene_elements_are_named(tmp_path):
    blobs = write_experiment(tmp_path, "blobs", {
        "ray": {"origin": [-3.0, 0.0, 0.0], "direction": [1.0, 0.0, 0.0]},
        "medium": {"type": "gaussian-blobs",
                   "blobs": [{"centre": [0, 0, 0], "amplitude": 1.0, "width": 0.5}]}},
        ["tau"])
    with pytest.raises(spec.SpecError, match="scene.medium.type"):
        runner.compute(blobs, quick=True, out_dir=tmp_path / "v", log=lambda *a: None)
    reduced = write_experiment(tmp_path, "reduced", {
        "ray": {"origin": [-3.0, 0.0, 0.0], "direction": [1.0, 0.0, 0.0]},
        "medium": {"type": "constant-sphere", "centre": [0, 0, 0], "radius": 1.0,
                   "kappa": 1.0},
        "light": {"toward_light": [-1.0, 0.0, 0.0], "intensity": 1.0}}, ["I_L"])
    with pytest.raises(spec.SpecError, match="scene.light.albedo"):
        runner.compute(reduced, quick=True, out_dir=tmp_path / "v", log=lambda *a: None)
    assert main([str(blobs), "--out", str(tmp_path / "v")]) == 2


def test_missing_mitsuba_message(monkeypatch):
    import builtins
    real_import = builtins.__import__

    def no_mitsuba(name, *args, **kwargs):
        if name in ("mitsuba", "drjit"):
            raise ImportError(f"No module named '{name}'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(mitsuba3, "_MI", None)
    monkeypatch.setattr(builtins, "__import__", no_mitsuba)
    with pytest.raises(mitsuba3.MitsubaMissing, match=r"pip install -r reference/requirements.txt"):
        mitsuba3.require_mitsuba()


# ---------------------------------------------------------------- rendering


def write_rendering(tmp_path, name, scene, quantities):
    return write_experiment(tmp_path, name, scene, quantities, family="rendering")


def rendering_value(path, quantity, passes=256):
    s = rendering.Settings(quick=True)
    s.passes = passes
    return rendering.compute(spec.load(path), quantity, s)


def within(result, expected, floor=1e-6):
    """Mitsuba's mean within 4 standard errors (plus a float32 floor) of an
    independent value."""
    diff = abs(result["value"] - expected)
    return diff <= 4.0 * result["std_error"] + floor * abs(expected)


def lambert_polygon(x, n, verts, radiance):
    """Irradiance at ``x`` (normal ``n``) from a Lambertian polygon wholly above
    the horizon and unoccluded: Lambert's contour formula,
    ``E = L/2 |sum_i Theta_i (unit(r_i x r_i+1) . n)|``."""
    r = [np.asarray(v, float) - np.asarray(x, float) for v in verts]
    r = [v / np.linalg.norm(v) for v in r]
    n = np.asarray(n, float) / np.linalg.norm(n)
    total = 0.0
    for a, b in zip(r, r[1:] + r[:1]):
        c = np.cross(a, b)
        total += math.atan2(np.linalg.norm(c), float(np.dot(a, b))) * float(np.dot(c, n)) \
            / np.linalg.norm(c)
    return radiance / 2.0 * abs(total)


RECEIVER = {"point": [0.1, -0.2, 0.05], "normal": [0.1, 0.2, 1.0]}


def test_rendering_disk_on_axis_closed_form(tmp_path):
    # E = pi L R^2 / (R^2 + h^2) under a coaxial disk facing the receiver.
    path = write_rendering(tmp_path, "disk", {
        "receiver": {"point": [0.3, 0.4, -1.0], "normal": [0.0, 0.0, 1.0]},
        "emitters": [{"type": "disk", "centre": [0.3, 0.4, -0.5], "normal": [0, 0, -1],
                      "radius": 1.0, "radiance": 2.0}]}, ["E_area", "E_cone"])
    res = rendering_value(path, "E_area")
    assert within(res, math.pi * 2.0 / 1.25), res
    assert rendering_value(path, "E_cone")["value"] == res["value"]


def test_rendering_triangle_and_parallelogram_by_lamberts_formula(tmp_path):
    tri = ([-0.4, 0.1, 1.2], [0.9, -0.3, 1.5], [0.2, 1.0, 0.9])
    # Winding chosen so that (b - a) x (c - b) faces the receiver below.
    a, b, c = (np.asarray(v) for v in tri)
    if float(np.dot(np.cross(b - a, c - b), np.asarray(RECEIVER["point"]) - a)) < 0:
        tri = (tri[0], tri[2], tri[1])
    path = write_rendering(tmp_path, "tri", {
        "receiver": RECEIVER,
        "emitters": [{"type": "triangle", "a": tri[0], "b": tri[1], "c": tri[2],
                      "radiance": 1.5}]}, ["E_area"])
    expected = lambert_polygon(RECEIVER["point"], RECEIVER["normal"], tri, 1.5)
    assert within(rendering_value(path, "E_area"), expected)

    o, eu, ev = np.array([-0.5, -0.3, 1.0]), np.array([1.1, 0.2, 0.1]), np.array([0.3, 0.9, 0.2])
    quad = [o, o + eu, o + eu + ev, o + ev]
    expected = lambert_polygon(RECEIVER["point"], RECEIVER["normal"], quad, 1.0)
    # edge_u x edge_v points up, away from the receiver: the back is dark.
    for edges, want in (((ev, eu), expected), ((eu, ev), 0.0)):
        path = write_rendering(tmp_path, "quad", {
            "receiver": RECEIVER,
            "emitters": [{"type": "rectangle", "origin": o.tolist(),
                          "edge_u": edges[0].tolist(), "edge_v": edges[1].tolist(),
                          "radiance": 1.0}]}, ["E_area"])
        res = rendering_value(path, "E_area")
        assert within(res, want) if want else res["value"] == 0.0, (edges, res)


def test_rendering_lambertian_radiance_is_albedo_over_pi_of_a_sphere_lights_irradiance(tmp_path):
    # A sphere wholly above the horizon: E = pi L (R / d)^2 cos theta.
    centre, radius = np.array([0.6, -0.3, 2.0]), 0.4
    d = np.linalg.norm(centre)
    cos_theta = centre[2] / d
    expected_e = math.pi * 3.0 * (radius / d) ** 2 * cos_theta
    path = write_rendering(tmp_path, "sph", {
        "receiver": {"point": [0, 0, 0], "normal": [0, 0, 1],
                     "brdf": {"type": "lambert", "albedo": 0.7},
                     "toward_viewer": [-0.5, 0.2, 1.0]},
        "emitters": [{"type": "sphere", "centre": centre.tolist(), "radius": radius,
                      "radiance": 3.0}]}, ["E_area", "L_area"])
    assert within(rendering_value(path, "E_area"), expected_e)
    assert within(rendering_value(path, "L_area"), 0.7 / math.pi * expected_e)


def test_rendering_environment_behind_an_occluder(tmp_path):
    # The sky (L = 1) less what a coaxial disk occluder hides: pi - pi R^2 / (R^2 + h^2).
    path = write_rendering(tmp_path, "sky", {
        "receiver": {"point": [0, 0, 0], "normal": [0, 0, 1]},
        "emitters": [{"type": "environment", "radiance": 1.0}],
        "occluders": [{"type": "disk", "centre": [0, 0, 2.0], "normal": [0, 0, 1],
                       "radius": 1.5}]}, ["E_hemisphere"])
    assert within(rendering_value(path, "E_hemisphere"), math.pi - math.pi * 2.25 / 6.25)


def test_rendering_light_a_millionth_above_the_receiver(tmp_path):
    """At the file's scale Mitsuba's shadow rays would start 8.9e-5 above the
    receiver, past a light 1e-6 above it; the scaled scene sees it."""
    path = write_rendering(tmp_path, "close", {
        "receiver": {"point": [0, 0, 0], "normal": [0, 0, 1]},
        "emitters": [{"type": "disk", "centre": [0, 0, 1e-6], "normal": [0, 0, -1],
                      "radius": 1.0, "radiance": 1.0}]}, ["E_cosine"])
    assert within(rendering_value(path, "E_cosine", passes=64), math.pi / (1.0 + 1e-12))


def test_rendering_what_mitsuba_cannot_do_is_named(tmp_path):
    phong = write_rendering(tmp_path, "phong", {
        "receiver": {"point": [0, 0, 0], "normal": [0, 0, 1],
                     "brdf": {"type": "phong", "k_s": 1.0, "exponent": 10},
                     "toward_viewer": [0, 0, 1]},
        "emitters": [{"type": "environment", "radiance": 1.0}]}, ["E_area", "L_brdf"])
    rec = runner.compute(phong, quick=True, out_dir=tmp_path / "v", log=lambda *a: None)
    assert set(rec["quantities"]) == {"E_area"}
    assert "no Phong BSDF" in rec["unsupported"]["L_brdf"]
    ggx = json.loads(phong.read_text())
    ggx["scene"]["receiver"]["brdf"] = {"type": "ggx", "alpha": 0.3}
    phong.write_text(json.dumps(ggx))
    assert "height-correlated" in rendering.unsupported_reason(spec.load(phong), "L_brdf")
    cap = write_rendering(tmp_path, "cap", {
        "receiver": {"point": [0, 0, 0], "normal": [0, 0, 1]},
        "emitters": [{"type": "environment", "radiance": 1.0},
                     {"type": "cap", "axis": [0, 0, 1], "half_angle": 0.1, "radiance": 1.0}]},
        ["E_area"])
    with pytest.raises(spec.SpecError) as err:
        runner.compute(cap, quick=True, out_dir=tmp_path / "v", log=lambda *a: None)
    assert err.value.path == "scene.emitters[1].type"
    assert not (tmp_path / "v" / "cap.json").exists()


# ---------------------------------------------------------------- furnace


def write_furnace(tmp_path, name, scene, quantities):
    return write_experiment(tmp_path, name, scene, quantities, family="furnace")


def test_furnace_series_and_its_truncation(tmp_path):
    # A closed enclosure emitting 2 with albedo 0.5: L_K = 2 sum_{k<=K} 0.5^k, L = 4.
    path = write_furnace(tmp_path, "f", {"albedo": 0.5, "emission": 2.0,
                                         "point": [0, 0, -1], "bounces": 2}, ["L", "L_K"])
    exp = spec.load(path)
    s = furnace.Settings(quick=True)
    s.bounces = 2e6
    lk = furnace.compute(exp, "L_K", s)
    assert lk["reflections"] == 2 and within(lk, 3.5), lk
    full = furnace.compute(exp, "L", s)
    assert 0.5 ** (full["reflections"] + 1) <= furnace.TRUNCATION
    assert within(full, 4.0), full


def test_furnace_float32_series_and_bound():
    # Powers of two sum exactly in float32 while the sum keeps 24 bits.
    assert furnace.float32_series(0.5, 1.0, 20) == 2.0 - 2.0 ** -20
    # 0.999 rounds to float32 0.99900001287..., whose series tends to
    # 1000.0129; the bound covers that and the float32 summation's drift.
    rho32 = float(np.float32(0.999))
    assert abs(1.0 / (1.0 - rho32) - 1000.0129) < 1e-4
    path_sum = furnace.float32_series(0.999, 1.0, 20000)
    assert 0.0 < abs(path_sum - 1.0 / (1.0 - rho32)) < 0.05


def test_furnace_cap_is_not_expressible(tmp_path):
    path = write_furnace(tmp_path, "cap", {"albedo": 0.9, "emission": 1.0, "half_angle": 0.5,
                                           "point": [0, 0, -1]}, ["L"])
    with pytest.raises(spec.SpecError) as err:
        runner.compute(path, quick=True, out_dir=tmp_path / "v", log=lambda *a: None)
    assert err.value.path == "scene.half_angle"


def test_mitsubas_sphere_seen_from_its_own_wall_is_biased(tmp_path):
    """Why the furnace is a cube: Mitsuba's sphere light sampled from a point
    on itself (path integrator, albedo 0.5, three reflections) is off by far
    more than its standard error, where the cube is not (L_3 = 1.875)."""
    mi, _ = mitsuba3.require_mitsuba()

    def l3(shape):
        scene = mi.load_dict({
            "type": "scene", "integrator": {"type": "path", "max_depth": 4, "rr_depth": 5},
            "walls": {"type": shape, "flip_normals": True,
                      "emitter": {"type": "area", "radiance": 1.0},
                      "bsdf": {"type": "diffuse", "reflectance": 0.5}},
            "sensor": {"type": "radiancemeter", "origin": [0, 0, 0], "direction": [0, 0, -1],
                       "film": {"type": "hdrfilm", "width": 1, "height": 1,
                                "rfilter": {"type": "box"}},
                       "sampler": {"type": "independent", "sample_count": 4096}}})
        v = np.array([float(np.mean(np.asarray(mi.render(scene, seed=k))[0, 0, :3]))
                      for k in range(16)])
        return v.mean(), v.std(ddof=1) / 4.0

    sphere, cube = l3("sphere"), l3("cube")
    assert abs(sphere[0] - 1.875) > 8.0 * sphere[1], sphere
    assert abs(cube[0] - 1.875) < 4.0 * cube[1], cube


# ---------------------------------------------------------------- bad input (hostile probe)


@pytest.mark.parametrize("change, path", [
    (lambda s: s.update(emitters=[{"type": "triangle", "a": [0, 0, 1], "b": [1, 0, 1],
                                   "c": [2, 0, 1], "radiance": 1}]), "scene.emitters[0]"),
    (lambda s: s.update(emitters=[{"type": "disk", "centre": [0, 0, 1], "normal": [0, 0, -1],
                                   "radius": float("nan"), "radiance": 1}]),
     "scene.emitters[0].radius"),
    (lambda s: s.update(emitters=[{"type": "sphere", "centre": [0, 0, 2], "radius": -1,
                                   "radiance": 1}]), "scene.emitters[0].radius"),
    (lambda s: s.update(receiver="abc"), "scene.receiver"),
    (lambda s: s["emitters"][0].update(radiance=1e300), "scene.emitters[0].radiance"),
    (lambda s: s["receiver"]["brdf"].pop("albedo"), "scene.receiver.brdf.albedo"),
    (lambda s: s["receiver"]["brdf"].update(albedo=True), "scene.receiver.brdf.albedo"),
    (lambda s: s.update(occluders="none"), "scene.occluders"),
])
def test_rendering_bad_scenes_are_named_and_write_nothing(tmp_path, change, path):
    scene = {"receiver": {"point": [0, 0, 0], "normal": [0, 0, 1],
                          "brdf": {"type": "lambert", "albedo": 0.5},
                          "toward_viewer": [0, 0, 1]},
             "emitters": [{"type": "disk", "centre": [0, 0, 1], "normal": [0, 0, -1],
                           "radius": 1.0, "radiance": 1.0}]}
    change(scene)
    bad = write_rendering(tmp_path, "bad", scene, ["E_area", "L_brdf"])
    with pytest.raises(spec.SpecError) as err:
        runner.compute(bad, quick=True, out_dir=tmp_path / "v", log=lambda *a: None)
    assert err.value.path == path
    assert not (tmp_path / "v" / "bad.json").exists()


def test_names_are_file_names_and_a_bad_file_does_not_stop_the_rest(tmp_path):
    good = write_rendering(tmp_path, "good", {
        "receiver": {"point": [0, 0, 0], "normal": [0, 0, 1]},
        "emitters": [{"type": "environment", "radiance": 1.0}]}, ["E_area"])
    escaping = json.loads(good.read_text())
    escaping["name"] = "../escaped"
    bad = tmp_path / "escaping.json"
    bad.write_text(json.dumps(escaping))
    with pytest.raises(spec.SpecError, match="file name") as err:
        spec.load(bad)
    assert err.value.path == "name"
    out = tmp_path / "v"
    assert main([str(bad), str(tmp_path / "absent.json"), str(good), "--quick",
                 "--out", str(out)]) == 2
    assert (out / "good.json").exists() and not (tmp_path / "escaped.json").exists()


def test_furnace_reflections_past_the_cap_are_refused(tmp_path):
    near_one = write_furnace(tmp_path, "near", {"albedo": 0.99999999, "emission": 1.0,
                                                "point": [0, 0, -1]}, ["L"])
    with pytest.raises(spec.SpecError) as err:
        runner.compute(near_one, quick=True, out_dir=tmp_path / "v", log=lambda *a: None)
    assert err.value.path == "scene.albedo"
    many = write_furnace(tmp_path, "many", {"albedo": 0.5, "emission": 1.0,
                                            "point": [0, 0, -1], "bounces": 5 * 10 ** 9},
                         ["L", "L_K"])
    with pytest.raises(spec.SpecError) as err:
        runner.compute(many, quick=True, out_dir=tmp_path / "v", log=lambda *a: None)
    assert err.value.path == "scene.bounces"
    assert not (tmp_path / "v" / "many.json").exists()
    for scene, path in (({"albedo": 0.5, "emission": 1e300, "point": [0, 0, -1]},
                         "scene.emission"),
                        ({"albedo": 0.5, "emission": 1.0, "half_angle": 4,
                          "point": [0, 0, -1]}, "scene.half_angle")):
        with pytest.raises(spec.SpecError) as err:
            spec.load(write_furnace(tmp_path, "x", scene, ["L"]))
        assert err.value.path == path


# ----------------------------------------------------------------------------
# whitted: pixel coverage


def write_whitted(tmp_path, name, scene, quantities=("coverage",)):
    doc = {"name": name, "family": "whitted", "description": "test", "equations": ["W-SS"],
           "scene": scene, "quantities": list(quantities),
           "rules": [{"rule": "grid"}], "budgets": [4], "reference": {"type": "closed-form"}}
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(doc, indent=2))
    return path


def clipped_area(poly, x0, y0):
    """The area of convex polygon ``poly`` (film points) inside the pixel
    square ``[x0, x0 + 1] x [y0, y0 + 1]`` (Sutherland-Hodgman, shoelace)."""
    for axis, bound, keep_above in ((0, x0, True), (0, x0 + 1, False),
                                    (1, y0, True), (1, y0 + 1, False)):
        out = []
        for i, p in enumerate(poly):
            q = poly[(i + 1) % len(poly)]
            pin = (p[axis] >= bound) == keep_above
            qin = (q[axis] >= bound) == keep_above
            if pin:
                out.append(p)
            if pin != qin:
                t = (bound - p[axis]) / (q[axis] - p[axis])
                out.append(p + t * (q - p))
        poly = out
        if not poly:
            return 0.0
    return 0.5 * abs(sum(poly[i][0] * poly[(i + 1) % len(poly)][1]
                         - poly[(i + 1) % len(poly)][0] * poly[i][1] for i in range(len(poly))))


def film_points(scene):
    """The triangle's corners on lightquad's film: ``x`` right from the left
    edge, ``y`` down from the top, in pixels (README, W-SS)."""
    forward = (scene.look_at - scene.eye) / np.linalg.norm(scene.look_at - scene.eye)
    right = np.cross(forward, scene.up)
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    t = math.tan(math.radians(scene.fov_y) / 2.0)
    w, h = scene.width, scene.height
    pts = []
    for p in scene.corners:
        v = p - scene.eye
        z = v @ forward
        sx, sy = (v @ right) / z, (v @ up) / z
        pts.append(np.array([(sx / (t * w / h) + 1.0) * w / 2.0, (1.0 - sy / t) * h / 2.0]))
    return pts


def test_whitted_every_pixel_of_mitsubas_image_is_the_covered_fraction(tmp_path):
    """The whole 8 x 6 film of the bundled edge-coverage scene (uncropped)
    against the polygon-clipped area of the projected triangle in each pixel:
    Mitsuba's camera, film orientation and box filter are lightquad's."""
    mi, _ = mitsuba3.require_mitsuba()
    exp = spec.load(REPO / "experiments" / "w-ss-edge-coverage.json")
    spp = 1 << 14
    scene = whitted.build_scene(exp, tmp_path, crop=False, spp=spp)
    img = np.asarray(mi.render(scene, spp=spp, seed=3), dtype=np.float64)[:, :, 0]
    pts = film_points(exp.scene)
    partial = 0
    for j in range(exp.scene.height):
        for i in range(exp.scene.width):
            c = clipped_area(pts, i, j)
            se = max(math.sqrt(c * (1.0 - c) / spp), 1e-6)
            assert abs(img[j, i] - c) < 5.0 * se, (i, j, img[j, i], c)
            partial += 0.0 < c < 1.0
    assert partial >= 8
    # The file's closed form, as its description quotes it.
    assert abs(clipped_area(pts, 3, 2) - 0.70627136950266) < 1e-12


def test_whitted_cropped_coverage_of_a_corner_triangle(tmp_path):
    """A small triangle inside one pixel of a 4 x 4 film: its cropped render
    is the triangle's area in pixels."""
    path = write_whitted(tmp_path, "corner", {
        "camera": {"eye": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "fov_y": 60.0,
                   "width": 4, "height": 4},
        "objects": [{"type": "triangle", "a": [0.02, 0.03, -1.0], "b": [0.25, 0.05, -1.0],
                     "c": [0.05, 0.27, -1.0], "material": {"k_a": 1.0}}],
        "pixel": [2, 1]})
    exp = spec.load(path)
    want = clipped_area(film_points(exp.scene), 2, 1)
    assert 0.05 < want < 0.95
    res = whitted.compute(exp, "coverage", whitted.Settings(quick=True))
    assert abs(res["value"] - want) < 4.0 * res["std_error"] + res["float32_error"], (res, want)


@pytest.mark.parametrize("change, path", [
    (lambda s: s["objects"].append(dict(s["objects"][0])), "scene.objects"),
    (lambda s: s["objects"][0].update(type="sphere"), "scene.objects"),
    (lambda s: s.update(objects="none"), "scene.objects"),
    (lambda s: s["objects"][0].update(c=[0.6, 0.0, -1.0]), "scene.objects[0]"),
    (lambda s: s["objects"][0].update(b="x"), "scene.objects[0].b"),
    (lambda s: s.update(pixel=[4, 0]), "scene.pixel[0]"),
    (lambda s: s["camera"].update(fov_y=0.0), "scene.camera.fov_y"),
    (lambda s: s["camera"].update(up=[0, 0, -1]), "scene.camera.up"),
    (lambda s: s["camera"].update(width=True), "scene.camera.width"),
])
def test_whitted_bad_scenes_are_named(tmp_path, change, path):
    scene = {"camera": {"eye": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0],
                        "fov_y": 60.0, "width": 4, "height": 4},
             "objects": [{"type": "triangle", "a": [0.0, 0.0, -1.0], "b": [0.3, 0.0, -1.0],
                          "c": [0.0, 0.3, -1.0], "material": {"k_a": 1.0}}],
             "pixel": [1, 1]}
    change(scene)
    bad = write_whitted(tmp_path, "bad", scene)
    with pytest.raises(spec.SpecError) as err:
        runner.compute(bad, quick=True, out_dir=tmp_path / "v", log=lambda *a: None)
    assert err.value.path == path
    assert not (tmp_path / "v" / "bad.json").exists()


# ----------------------------------------------------------------------------
# Server mode: Mitsuba 3 as a lightquad external estimator (lqref.serve)


def _furnace_request(budget, channels=1, family="furnace"):
    return {"protocol": "lightquad-estimator", "version": 1, "id": 7, "experiment": "t",
            "family": family, "scene": {"albedo": 0.5, "emission": 1.0, "half_angle": math.pi},
            "quantity": "L", "channels": channels, "dimension": 2, "budget": budget,
            "seed": 3, "repeat": 0}


def test_serve_answers_the_furnace_within_its_standard_error():
    from lqref import serve

    # The white furnace: L = L_e / (1 - rho) = 2 (truncation of Mitsuba's
    # paths at the harness's depth aside, far below the noise here).
    r = serve.answer(_furnace_request(512))
    assert r["id"] == 7 and r["evaluations"] == 512
    assert len(r["value"]) == 1 and len(r["std_error"]) == 1
    assert abs(r["value"][0] - 2.0) < 5 * r["std_error"][0] + 1e-3, r
    assert r["seconds"] > 0


def test_serve_declines_what_it_cannot_compute():
    from lqref import serve

    assert "channels" in serve.answer(_furnace_request(16, channels=3))["error"]
    assert "family" in serve.answer(_furnace_request(16, family="integral"))["error"]
    bad = _furnace_request(16)
    bad["scene"] = {"albedo": "white"}
    assert "error" in serve.answer(bad)


def test_serve_speaks_the_protocol_over_pipes():
    request = json.dumps(_furnace_request(64)) + "\n"
    done = subprocess.run([sys.executable, str(Path(__file__).resolve().parent.parent / "serve.py")],
                          input=request, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    hello, answer = done.stdout.splitlines()
    assert json.loads(hello) == {"protocol": "lightquad-estimator", "version": 1}
    assert json.loads(answer)["id"] == 7


# ----------------------------------------------------------------------------
# exchange: a receiving patch's mean irradiance by an irradiance meter


def c11(a, b, c):
    """Howell C-11: directly opposed a x b rectangles at distance c."""
    x, y = a / c, b / c
    return 2 / (math.pi * x * y) * (
        math.log(math.sqrt((1 + x * x) * (1 + y * y) / (1 + x * x + y * y)))
        + x * math.sqrt(1 + y * y) * math.atan(x / math.sqrt(1 + y * y))
        + y * math.sqrt(1 + x * x) * math.atan(y / math.sqrt(1 + x * x))
        - x * math.atan(x) - y * math.atan(y))


def exchange_values(path, passes=256):
    s = exchange.Settings(quick=True)
    s.passes = passes
    exp = spec.load(path)
    return {q: exchange.compute(exp, q, s) for q in ("F_area", "Phi_cone", "E_mean_contour")}


def test_exchange_opposed_rectangles_give_howells_c11(tmp_path):
    # A 2 x 1 receiver under the same rectangle at height 0.5, radiance 3.
    path = write_experiment(tmp_path, "opp", {
        "receiver": {"type": "rectangle", "origin": [0, 0, 0], "edge_u": [2, 0, 0],
                     "edge_v": [0, 1, 0]},
        "emitters": [{"type": "rectangle", "origin": [0, 0, 0.5], "edge_u": [0, 1, 0],
                      "edge_v": [2, 0, 0], "radiance": 3.0}]},
        ["F_area", "Phi_cone", "E_mean_contour"], family="exchange")
    f = c11(2.0, 1.0, 0.5)
    v = exchange_values(path)
    assert within(v["F_area"], f), v["F_area"]
    assert within(v["E_mean_contour"], math.pi * 3.0 * f), v["E_mean_contour"]
    assert within(v["Phi_cone"], 2.0 * math.pi * 3.0 * f), v["Phi_cone"]


def test_exchange_light_facing_away_gives_zero_and_bad_scenes_are_named(tmp_path):
    away = {"receiver": {"type": "disk", "centre": [0, 0, 0], "normal": [0, 0, 1],
                         "radius": 1.0},
            "emitters": [{"type": "disk", "centre": [0, 0, 1], "normal": [0, 0, 1],
                          "radius": 1.0, "radiance": 1.0}]}
    path = write_experiment(tmp_path, "away", away, ["F_area"], family="exchange")
    assert exchange_values(path)["F_area"]["value"] == 0.0
    bad = dict(away, emitters=[{"type": "sphere", "centre": [0, 0, 2], "radius": 0.5,
                                "radiance": 1.0}])
    with pytest.raises(spec.SpecError, match=r"scene\.emitters\[0\]\.type"):
        exchange.read_scene(bad)
    with pytest.raises(spec.SpecError, match=r"scene\.receiver\.type"):
        exchange.read_scene(dict(away, receiver={"type": "sphere"}))
