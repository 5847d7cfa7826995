#!/usr/bin/env python3
"""The peers of issue 32: penumbra's passes side by side with Mitsuba 3 (Embree) and Mesa's
llvmpipe, on one scene, in one run.

    scripts/peers/.venv/bin/python scripts/peers/run.py SCENE [--out DIR] [--runs N] [--size W]
                                                     [--opt METHOD.KEY=VALUE]...

SCENE is a penumbra scene file (TOML or JSON) or a built-in scene name. The script

1. calls the release binary's `export-scene` for the geometry, camera, `raycast`'s light
   samples and `hard-sv`'s shadow-volume triangles (docs/cli.md);
2. renders the scene N times with penumbra (`render --methods hard-sv,ssv,raycast` with
   `raycast.samples=16`, then `render --methods raycast` with `raycast.samples=1024`) and
   reads every pass's `wall_seconds` from `stats.json` and the visibility from
   `visibility.pfm`;
3. Mitsuba 3 (`llvm_ad_rgb`, Embree on the CPU): casts one primary ray per pixel center
   (the receivers: the hit point and its geometric normal turned to the camera; penumbra's own
   receivers are depth-buffer points, which the export does not carry, so the two differ by
   the depth quantization and at silhouettes), then from each receiver the shadow rays to
   the same light samples as `raycast` with the same origin offset, segment epsilon and
   self-occlusion rule (src/methods/raycast.rs), at 16 and 1024 samples. Timed: the
   `ray_test` of all shadow rays (built and evaluated beforehand), warm (after one untimed
   run that compiles the kernel), N runs;
4. llvmpipe through EGL (surfaceless, OpenGL 3.3 core): a framebuffer object with
   DEPTH24_STENCIL8, the scene's depth pass from the exported clip coordinates, then
   `hard-sv`'s shadow-volume triangles with two-sided wrapping stencil (z-fail or z-pass as
   penumbra chose; depth clamp on for z-fail, so that caps at infinity are not clipped).
   Timed: one warm frame (clear, both passes, glFinish), N runs after one untimed frame;
   its shadow mask (stencil != 0) against `hard-sv`'s visibility.

It writes DIR/peers.md and DIR/peers.json (default DIR: out/peers/SCENE). Errors: mean |e|
over the pixels that have a receiver in both renders; llvmpipe: the fraction of receiver
pixels whose lit/shadow verdict differs from hard-sv's, and mean |e| of its 0/1 mask
against raycast at 1024 samples.

`run.py --check` only checks that both peers start (scripts/peers/setup.sh runs it).
"""

from __future__ import annotations

import argparse
import ctypes
import json
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "egl")

import numpy as np  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
SAMPLES = (16, 1024)
# src/methods/raycast.rs: ORIGIN_OFFSET, ORIGIN_OFFSET_ULPS, SEGMENT_EPSILON.
ORIGIN_OFFSET = 1e-4
ORIGIN_OFFSET_ULPS = 2.0
SEGMENT_EPSILON = 1e-6
F32_EPS = float(np.finfo(np.float32).eps)


# ---------------------------------------------------------------------------------------------
# Small helpers


def summary(times: list[float]) -> dict:
    """Median, min and max of `times` (seconds) and their count."""
    return {
        "seconds": {
            "median": statistics.median(times),
            "min": min(times),
            "max": max(times),
        },
        "runs": len(times),
    }


def read_pfm(path: Path) -> np.ndarray:
    """A PFM image as float32, shape (H, W) or (H, W, 3), row 0 at the top."""
    data = path.read_bytes()
    header = re.match(rb"(P[fF])\s+(\d+)\s+(\d+)\s+(\S+)\s", data)
    if header is None:
        raise ValueError(f"{path}: not a PFM file")
    kind, w, h, scale = header.groups()
    channels = 3 if kind == b"PF" else 1
    dtype = "<f4" if float(scale) < 0 else ">f4"
    pixels = np.frombuffer(data, dtype=dtype, offset=header.end())
    shape = (int(h), int(w), 3) if channels == 3 else (int(h), int(w))
    return pixels[: int(w) * int(h) * channels].reshape(shape)[::-1].astype(np.float32)


def gray(v: np.ndarray) -> np.ndarray:
    """One visibility per pixel (the mean of RGB visibility)."""
    return v.mean(axis=2) if v.ndim == 3 else v


def penumbra_binary(explicit: str | None) -> Path:
    """The release binary: `--penumbra`, else target/release/penumbra, built if missing."""
    if explicit:
        return Path(explicit)
    path = REPO / "target" / "release" / "penumbra"
    if not path.exists():
        print("run.py: cargo build --release", file=sys.stderr)
        subprocess.run(["cargo", "build", "--release"], cwd=REPO, check=True)
    return path


def scene_name(scene: str) -> str:
    """The scene's name in file names: the built-in name or the file's stem."""
    p = Path(scene)
    name = p.stem if p.suffix in (".toml", ".json") else scene
    return re.sub(r"[^A-Za-z0-9_-]", "-", name)


# ---------------------------------------------------------------------------------------------
# penumbra


def run_penumbra(exe: Path, args: list[str]) -> None:
    """Runs penumbra with `args`; its stdout is not needed."""
    subprocess.run([str(exe), *args], check=True, stdout=subprocess.DEVNULL)


def export(exe: Path, scene: str, size: list[str], samples: int, tmp: Path) -> dict:
    """penumbra's export document of the scene at `samples` light samples."""
    out = tmp / f"export-{samples}.json"
    run_penumbra(
        exe,
        ["export-scene", scene, *size, "--opt", f"raycast.samples={samples}", "--out", str(out)],
    )
    return json.loads(out.read_text())


def penumbra_run(exe: Path, scene: str, size: list[str], k: int, tmp: Path, result: dict) -> None:
    """Run `k` of penumbra, added to `result`: renders hard-sv, ssv and raycast at 16 samples,
    then raycast at 1024; per method (`raycast-16`, `raycast-1024`) and pass the lists of
    `wall_seconds`, the method's whole `wall_seconds` (`total`), the pass order, and the
    visibility of the latest run."""
    jobs = {
        "16": (["hard-sv", "ssv", "raycast"], 16),
        "1024": (["raycast"], 1024),
    }
    for tag, (methods, samples) in jobs.items():
        out = tmp / f"penumbra-{tag}-{k}"
        run_penumbra(
            exe,
            [
                "render", scene, *size, "--methods", ",".join(methods),
                "--opt", f"raycast.samples={samples}", "--out", str(out),
            ],
        )
        for m in methods:
            key = m if m != "raycast" else f"raycast-{samples}"
            stats = json.loads((out / m / "stats.json").read_text())
            entry = result.setdefault(key, {"passes": {}, "total": [], "order": []})
            for p in stats["passes"]:
                if p["name"] not in entry["passes"]:
                    entry["order"].append(p["name"])
                entry["passes"].setdefault(p["name"], []).append(p["wall_seconds"])
            entry["total"].append(stats["wall_seconds"])
            entry["visibility"] = gray(read_pfm(out / m / "visibility.pfm"))
        shutil.rmtree(out)


# ---------------------------------------------------------------------------------------------
# Mitsuba 3 (Embree)


def mitsuba():
    """Mitsuba with the llvm_ad_rgb variant, Dr.Jit with it."""
    import drjit as dr
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    return mi, dr


def mitsuba_scene(mi, meshes: list[dict]):
    """A Mitsuba scene of `meshes` (export documents' meshes), or None if there are none."""
    shapes = {}
    for k, m in enumerate(meshes):
        pos = np.asarray(m["positions"], dtype=np.float32)
        tri = np.asarray(m["triangles"], dtype=np.uint32)
        mesh = mi.Mesh(f"m{k}", len(pos) // 3, len(tri) // 3, has_vertex_normals=False)
        params = mi.traverse(mesh)
        params["vertex_positions"] = mi.Float(pos)
        params["faces"] = mi.UInt32(tri)
        params.update()
        shapes[f"m{k}"] = mesh
    if not shapes:
        return None
    return mi.load_dict({"type": "scene", **shapes})


def primary_receivers(mi, dr, doc: dict, scene) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The receiver of every pixel center (row-major, row 0 at the top) as penumbra's
    `Projection::unproject` defines the pixel ray: (hit mask, points, camera-side normals)."""
    w, h = doc["width"], doc["height"]
    vp = np.asarray(doc["camera"]["view_proj"], dtype=np.float64).reshape(4, 4).T
    inv = np.linalg.inv(vp)
    xs, ys = np.meshgrid(np.arange(w), np.arange(h))
    ndc = np.stack(
        [
            (xs.ravel() + 0.5) / w * 2.0 - 1.0,
            1.0 - (ys.ravel() + 0.5) / h * 2.0,
            np.zeros(w * h),
            np.ones(w * h),
        ]
    )
    far = inv @ ndc
    far = (far[:3] / far[3]).T
    eye = np.asarray(doc["camera"]["eye"], dtype=np.float64)
    d = far - eye
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    ray = mi.Ray3f(
        mi.Point3f(*[np.full(w * h, c, dtype=np.float32) for c in eye]),
        mi.Vector3f(*[d[:, c].astype(np.float32) for c in range(3)]),
    )
    si = scene.ray_intersect(ray)
    valid = si.is_valid()
    n = si.n
    n = dr.select(dr.dot(n, ray.d) > 0, -n, n)
    dr.eval(valid, si.p, n)
    hit = np.asarray(valid, dtype=bool)
    p = np.stack([np.asarray(si.p[c]) for c in range(3)], axis=1)
    nn = np.stack([np.asarray(n[c]) for c in range(3)], axis=1)
    return hit, p[hit], nn[hit]


def mesh_extent(meshes: list[dict]) -> tuple[float, float]:
    """D, the diagonal of the meshes' bounds (f32), and M, their largest coordinate magnitude."""
    pos = np.concatenate([np.asarray(m["positions"], dtype=np.float32) for m in meshes])
    pos = pos.reshape(-1, 3)
    diag = float(np.linalg.norm((pos.max(axis=0) - pos.min(axis=0)).astype(np.float32)))
    return diag, float(np.abs(pos).max())


def orthonormal_basis(dr, n):
    """src/light/sampling.rs `orthonormal_basis` (Duff et al. 2017) for Dr.Jit vectors."""
    import mitsuba as mi

    n = dr.normalize(n)
    sign = dr.select(n.z >= 0, 1.0, -1.0)
    a = -1.0 / (sign + n.z)
    b = n.x * n.y * a
    b1 = mi.Vector3f(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x)
    b2 = mi.Vector3f(b, sign + n.y * n.y * a, -n.y)
    return b1, b2


def shadow_rays(mi, dr, doc: dict, points: np.ndarray, normals: np.ndarray):
    """Every receiver's shadow rays to `raycast`'s samples (src/methods/raycast.rs "Shadow
    rays", "Self-occlusion"), evaluated: (rays, index of each ray's (receiver, sample) pair,
    the mask of pairs facing the light)."""
    samples = doc["samples"]
    light = doc["light"]
    ns, nr = samples["count"], len(points)
    diag, magnitude = mesh_extent(doc["meshes"])
    delta = ORIGIN_OFFSET * diag + ORIGIN_OFFSET_ULPS * F32_EPS * magnitude
    i = dr.arange(mi.UInt32, nr * ns)
    pix = i // ns
    smp = i - pix * ns
    p = dr.gather(mi.Point3f, mi.Point3f(*[points[:, c] for c in range(3)]), pix)
    n = dr.gather(mi.Vector3f, mi.Vector3f(*[normals[:, c] for c in range(3)]), pix)
    if light["type"] == "sphere":
        disk = np.asarray(samples["unit_disk"], dtype=np.float32)
        ab = dr.gather(mi.Point2f, mi.Point2f(disk[:, 0], disk[:, 1]), smp)
        c = mi.Point3f(*light["center"])
        b1, b2 = orthonormal_basis(dr, p - c)
        s = c + light["radius"] * (ab.x * b1 + ab.y * b2)
    else:
        pos = np.asarray(samples["positions"], dtype=np.float32)
        s = dr.gather(mi.Point3f, mi.Point3f(*[pos[:, c] for c in range(3)]), smp)
    facing = dr.dot(n, s - p) > 0
    o = p + delta * n
    v = s - o
    length = dr.norm(v)
    d = v / length
    # dr.minimum lowers to llvm.minimum, which LLVM 15 cannot select on x86: a select instead.
    start = SEGMENT_EPSILON * dr.select(length < diag, length, diag)
    o = o + d * start
    maxt = length * (1.0 - SEGMENT_EPSILON) - start
    dr.eval(facing, o, d, maxt)
    sel = dr.compress(facing)

    def pick(v):
        return [dr.gather(mi.Float, v[c], sel) for c in range(3)]

    ray = mi.Ray3f(mi.Point3f(*pick(o)), mi.Vector3f(*pick(d)), dr.gather(mi.Float, maxt, sel))
    dr.eval(ray)
    return ray, np.asarray(sel), np.asarray(facing, dtype=bool)


class MitsubaPeer:
    """Mitsuba's shadow rays at one export document's sample count. Set up (scenes, primary
    rays, the shadow rays built and evaluated) and run once untimed (the kernel compiles) on
    creation; each `run` then times, warm, building the casters' scene (Embree's BVH) and the
    `ray_test` of every shadow ray."""

    def __init__(self, mi, dr, doc: dict):
        self.mi, self.dr, self.doc = mi, dr, doc
        self.casters_meshes = [m for m in doc["meshes"] if not m["receiver_only"]]
        everything = mitsuba_scene(mi, doc["meshes"])
        t0 = time.perf_counter()
        self.hit, points, normals = primary_receivers(mi, dr, doc, everything)
        self.primary = time.perf_counter() - t0
        self.receivers = len(points)
        self.ray, self.sel, self.facing = shadow_rays(mi, dr, doc, points, normals)
        self.rays = len(self.sel)
        self.build: list[float] = []
        self.times: list[float] = []
        self.blocked = None
        self.run(timed=False)

    def run(self, timed: bool = True) -> None:
        """One run of both timed parts."""
        mi, dr = self.mi, self.dr
        t0 = time.perf_counter()
        casters = mitsuba_scene(mi, self.casters_meshes)
        t1 = time.perf_counter()
        if casters is None:
            blocked = dr.zeros(mi.Bool, self.rays)
        else:
            blocked = casters.ray_test(self.ray)
        dr.eval(blocked)
        dr.sync_thread()
        t2 = time.perf_counter()
        if timed:
            self.build.append(t1 - t0)
            self.times.append(t2 - t1)
        self.blocked = blocked

    def image(self) -> np.ndarray:
        """The visibility of every pixel (row 0 at the top; background 1, as raycast)."""
        doc = self.doc
        ns = doc["samples"]["count"]
        weights = np.asarray(doc["samples"]["weights"], dtype=np.float64)
        if weights.ndim == 2:
            weights = weights.mean(axis=1)
        lit = np.zeros(self.receivers * ns, dtype=bool)
        lit[self.sel] = ~np.asarray(self.blocked, dtype=bool)
        lit &= self.facing
        lit = lit.reshape(self.receivers, ns)
        vis = (lit * weights).sum(axis=1) / weights.sum()
        image = np.ones(doc["width"] * doc["height"], dtype=np.float64)
        image[self.hit] = vis
        return image.reshape(doc["height"], doc["width"])


# ---------------------------------------------------------------------------------------------
# llvmpipe (OpenGL through EGL)

EGL_PLATFORM_SURFACELESS_MESA = 0x31DD

VERTEX_SHADER = """#version 330 core
layout(location = 0) in vec4 clip;
void main() { gl_Position = clip; }
"""
FRAGMENT_SHADER = """#version 330 core
out vec4 colour;
void main() { colour = vec4(1.0); }
"""


def egl_context():
    """An OpenGL 3.3 core context on Mesa's surfaceless EGL platform (llvmpipe here)."""
    from OpenGL import EGL
    from OpenGL.EGL.EXT.platform_base import eglGetPlatformDisplayEXT

    dpy = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL.EGL_DEFAULT_DISPLAY, None)
    major, minor = EGL.EGLint(), EGL.EGLint()
    if not EGL.eglInitialize(dpy, ctypes.pointer(major), ctypes.pointer(minor)):
        raise RuntimeError("eglInitialize failed")
    EGL.eglBindAPI(EGL.EGL_OPENGL_API)
    config, count = EGL.EGLConfig(), EGL.EGLint()
    attrs = (EGL.EGLint * 5)(
        EGL.EGL_RENDERABLE_TYPE, EGL.EGL_OPENGL_BIT,
        EGL.EGL_SURFACE_TYPE, EGL.EGL_PBUFFER_BIT,
        EGL.EGL_NONE,
    )
    EGL.eglChooseConfig(dpy, attrs, ctypes.pointer(config), 1, ctypes.pointer(count))
    if count.value < 1:
        raise RuntimeError("no EGL config with OpenGL")
    ctx_attrs = (EGL.EGLint * 7)(
        EGL.EGL_CONTEXT_MAJOR_VERSION, 3,
        EGL.EGL_CONTEXT_MINOR_VERSION, 3,
        EGL.EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL.EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
        EGL.EGL_NONE,
    )
    ctx = EGL.eglCreateContext(dpy, config, EGL.EGL_NO_CONTEXT, ctx_attrs)
    if not ctx or not EGL.eglMakeCurrent(dpy, EGL.EGL_NO_SURFACE, EGL.EGL_NO_SURFACE, ctx):
        raise RuntimeError("cannot make an OpenGL 3.3 core context current")
    return dpy, ctx


def gl_program(GL):
    """The pass-through program: clip coordinates in, a constant colour out."""
    from OpenGL.GL import shaders

    return shaders.compileProgram(
        shaders.compileShader(VERTEX_SHADER, GL.GL_VERTEX_SHADER),
        shaders.compileShader(FRAGMENT_SHADER, GL.GL_FRAGMENT_SHADER),
    )


def gl_vertices(GL, clip: np.ndarray):
    """A vertex array of vec4 clip coordinates at attribute 0, drawn as GL_TRIANGLES."""
    vao = GL.glGenVertexArrays(1)
    GL.glBindVertexArray(vao)
    vbo = GL.glGenBuffers(1)
    GL.glBindBuffer(GL.GL_ARRAY_BUFFER, vbo)
    GL.glBufferData(GL.GL_ARRAY_BUFFER, clip.nbytes, clip, GL.GL_STATIC_DRAW)
    GL.glEnableVertexAttribArray(0)
    GL.glVertexAttribPointer(0, 4, GL.GL_FLOAT, GL.GL_FALSE, 0, None)
    GL.glBindVertexArray(0)
    return vao, len(clip) // 4


class LlvmpipePeer:
    """The z-fail (or z-pass) stencil shadow-volume frame on llvmpipe. Set up (context,
    framebuffer, vertex buffers) and drawn once untimed on creation; each `run` times one warm
    frame; `finish` reads the masks back and releases the context."""

    def __init__(self, doc: dict):
        from OpenGL import GL

        self.doc = doc
        self.dpy, self.ctx = egl_context()
        self.renderer = GL.glGetString(GL.GL_RENDERER).decode()
        self.times: list[float] = []
        self.frame = self.setup(GL, doc)
        self.frame()

    def run(self) -> None:
        """One timed frame."""
        t0 = time.perf_counter()
        self.frame()
        self.times.append(time.perf_counter() - t0)

    def finish(self) -> tuple[np.ndarray, np.ndarray]:
        """The shadow mask (stencil ≠ 0) and the receiver mask (depth < 1), row 0 at the top."""
        from OpenGL import EGL, GL

        w, h = self.doc["width"], self.doc["height"]
        GL.glPixelStorei(GL.GL_PACK_ALIGNMENT, 1)
        stencil = GL.glReadPixels(0, 0, w, h, GL.GL_STENCIL_INDEX, GL.GL_UNSIGNED_BYTE)
        stencil = np.frombuffer(stencil, dtype=np.uint8).reshape(h, w)[::-1]
        zbuf = GL.glReadPixels(0, 0, w, h, GL.GL_DEPTH_COMPONENT, GL.GL_FLOAT)
        zbuf = np.frombuffer(zbuf, dtype=np.float32).reshape(h, w)[::-1]
        EGL.eglMakeCurrent(self.dpy, EGL.EGL_NO_SURFACE, EGL.EGL_NO_SURFACE, EGL.EGL_NO_CONTEXT)
        EGL.eglDestroyContext(self.dpy, self.ctx)
        EGL.eglTerminate(self.dpy)
        return stencil != 0, zbuf < 1.0

    @staticmethod
    def setup(GL, doc: dict):
        """The framebuffer, program and vertex arrays of `doc`; returns the frame function."""
        w, h = doc["width"], doc["height"]
        fbo = GL.glGenFramebuffers(1)
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, fbo)
        colour, depth = GL.glGenRenderbuffers(2)
        GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, colour)
        GL.glRenderbufferStorage(GL.GL_RENDERBUFFER, GL.GL_RGBA8, w, h)
        GL.glFramebufferRenderbuffer(
            GL.GL_FRAMEBUFFER, GL.GL_COLOR_ATTACHMENT0, GL.GL_RENDERBUFFER, colour
        )
        GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, depth)
        GL.glRenderbufferStorage(GL.GL_RENDERBUFFER, GL.GL_DEPTH24_STENCIL8, w, h)
        GL.glFramebufferRenderbuffer(
            GL.GL_FRAMEBUFFER, GL.GL_DEPTH_STENCIL_ATTACHMENT, GL.GL_RENDERBUFFER, depth
        )
        if GL.glCheckFramebufferStatus(GL.GL_FRAMEBUFFER) != GL.GL_FRAMEBUFFER_COMPLETE:
            raise RuntimeError("incomplete framebuffer")
        GL.glViewport(0, 0, w, h)
        GL.glUseProgram(gl_program(GL))
        scene_clip = np.concatenate(
            [
                np.asarray(m["clip_positions"], dtype=np.float32)
                .reshape(-1, 4)[np.asarray(m["triangles"], dtype=np.int64)]
                .ravel()
                for m in doc["meshes"]
            ]
        )
        scene_vao, scene_n = gl_vertices(GL, scene_clip)
        volume_vao, volume_n = gl_vertices(
            GL, np.asarray(doc["hard_sv"]["volume_clip"], dtype=np.float32)
        )
        zfail = doc["hard_sv"]["mode"] == "zfail"

        def frame():
            GL.glDepthMask(GL.GL_TRUE)
            GL.glStencilMask(0xFF)
            GL.glClearDepth(1.0)
            GL.glClearStencil(0)
            GL.glClear(GL.GL_DEPTH_BUFFER_BIT | GL.GL_STENCIL_BUFFER_BIT)
            GL.glColorMask(GL.GL_FALSE, GL.GL_FALSE, GL.GL_FALSE, GL.GL_FALSE)
            GL.glDisable(GL.GL_CULL_FACE)
            GL.glEnable(GL.GL_DEPTH_TEST)
            GL.glDepthFunc(GL.GL_LESS)
            GL.glDisable(GL.GL_STENCIL_TEST)
            GL.glDisable(GL.GL_DEPTH_CLAMP)
            GL.glBindVertexArray(scene_vao)
            GL.glDrawArrays(GL.GL_TRIANGLES, 0, scene_n)
            GL.glDepthMask(GL.GL_FALSE)
            GL.glEnable(GL.GL_STENCIL_TEST)
            GL.glStencilFunc(GL.GL_ALWAYS, 0, 0xFF)
            if zfail:
                GL.glEnable(GL.GL_DEPTH_CLAMP)
                GL.glStencilOpSeparate(GL.GL_BACK, GL.GL_KEEP, GL.GL_INCR_WRAP, GL.GL_KEEP)
                GL.glStencilOpSeparate(GL.GL_FRONT, GL.GL_KEEP, GL.GL_DECR_WRAP, GL.GL_KEEP)
            else:
                GL.glStencilOpSeparate(GL.GL_FRONT, GL.GL_KEEP, GL.GL_KEEP, GL.GL_INCR_WRAP)
                GL.glStencilOpSeparate(GL.GL_BACK, GL.GL_KEEP, GL.GL_KEEP, GL.GL_DECR_WRAP)
            GL.glBindVertexArray(volume_vao)
            GL.glDrawArrays(GL.GL_TRIANGLES, 0, volume_n)
            GL.glFinish()

        return frame


# ---------------------------------------------------------------------------------------------
# The report


def mean_abs(a: np.ndarray, b: np.ndarray, mask: np.ndarray) -> float:
    """Mean |a − b| over `mask`."""
    return float(np.abs(a[mask].astype(np.float64) - b[mask]).mean()) if mask.any() else 0.0


def fmt(s: float) -> str:
    """Seconds with 3 significant digits."""
    return f"{s:.3g}"


def write_report(out: Path, doc: dict) -> None:
    """DIR/peers.json (the document) and DIR/peers.md (its table)."""
    out.mkdir(parents=True, exist_ok=True)
    (out / "peers.json").write_text(json.dumps(doc, indent=2) + "\n")
    lines = [
        f"# Peers: `{doc['scene']}` at {doc['width']}×{doc['height']}"
        + "".join(f", `{o}`" for o in doc["options"]),
        "",
        f"{doc['machine']}; medians of {doc['runs']} runs in one run of `scripts/peers/run.py`. "
        "Seconds per pass; *ratio* is penumbra's median over the peer's for the rows of "
        "issue 32 (below 1: penumbra faster).",
        "",
        "| peer | pass | median s | min s | max s | runs | error vs raycast |",
        "|---|---|---|---|---|---|---|",
    ]
    for peer in doc["peers"]:
        for p in peer["passes"]:
            s = p["seconds"]
            err = p.get("error", "")
            lines.append(
                f"| {peer['name']} | {p['name']} | {fmt(s['median'])} | {fmt(s['min'])} | "
                f"{fmt(s['max'])} | {p['runs']} | {err} |"
            )
    lines += ["", "| issue 32 row | penumbra s | peer s | ratio penumbra/peer | goal | met |"]
    lines.append("|---|---|---|---|---|---|")
    for r in doc["rows"]:
        met = "yes" if r["ratio"] <= r["goal"] else "no"
        lines.append(
            f"| {r['row']} | {fmt(r['penumbra'])} | {fmt(r['peer'])} | {r['ratio']:.2f}× | "
            f"{r['goal_text']} | {met} |"
        )
    lines += ["", "Errors:", ""]
    for peer in doc["peers"]:
        for k, v in peer["error"].items():
            lines.append(f"- {peer['name']}, {k}: {v}")
    (out / "peers.md").write_text("\n".join(lines) + "\n")


def pass_entry(name: str, times: list[float], error: str = "") -> dict:
    """One pass of peers.json."""
    e = {"name": name, **summary(times)}
    if error:
        e["error"] = error
    return e


def hard_sv_passes(entry: dict) -> tuple[str, list[float]]:
    """hard-sv's scene depth and stencil passes summed per run (what the GL frame does)."""
    names = [n for n in entry["order"] if "depth" in n or "shadow-volume" in n or "stencil" in n]
    per_run = [sum(entry["passes"][n][k] for n in names) for k in range(len(entry["total"]))]
    return " + ".join(names), per_run


def wedge_pass(entry: dict) -> tuple[str, list[float]]:
    """ssv's wedge pass (the one named for wedges), or its slowest pass."""
    names = [n for n in entry["order"] if "wedge" in n]
    name = names[0] if names else max(entry["order"], key=lambda n: statistics.median(entry["passes"][n]))
    return name, entry["passes"][name]


def ray_pass(entry: dict) -> tuple[str, list[float]]:
    """raycast's shadow-ray pass (its slowest pass)."""
    name = max(entry["order"], key=lambda n: statistics.median(entry["passes"][n]))
    return name, entry["passes"][name]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", nargs="?", help="scene file (.toml/.json) or built-in name")
    ap.add_argument("--out", type=Path, help="output directory (default out/peers/SCENE)")
    ap.add_argument("--runs", type=int, default=5, help="timed runs per pass (default 5)")
    ap.add_argument("--size", type=int, help="image width (height follows the aspect ratio)")
    ap.add_argument("--penumbra", help="the penumbra binary (default target/release/penumbra)")
    ap.add_argument(
        "--opt",
        action="append",
        default=[],
        metavar="METHOD.KEY=VALUE",
        help="a penumbra option for export-scene and every render (e.g. hard-sv.mode=zfail)",
    )
    ap.add_argument("--check", action="store_true", help="only check that both peers start")
    a = ap.parse_args()
    if a.check:
        mi, dr = mitsuba()
        gl = LlvmpipePeer(check_doc())
        gl.finish()
        print(f"peers: mitsuba {mi.__version__} ({mi.variant()}), OpenGL on {gl.renderer}")
        return 0
    if not a.scene or a.runs < 1:
        ap.error("SCENE is required and --runs must be at least 1")
    exe = penumbra_binary(a.penumbra)
    size = ["--width", str(a.size)] if a.size else []
    for o in a.opt:
        size += ["--opt", o]
    out = a.out or REPO / "out" / "peers" / scene_name(a.scene)
    mi, dr = mitsuba()
    load_before = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="penumbra-peers-") as tmpdir:
        tmp = Path(tmpdir)
        docs = {n: export(exe, a.scene, size, n, tmp) for n in SAMPLES}
        doc16 = docs[16]
        w, h = doc16["width"], doc16["height"]
        mits = {n: MitsubaPeer(mi, dr, docs[n]) for n in SAMPLES}
        gl_peer = LlvmpipePeer(doc16)
        # The peers' runs in turn, so that a drift of a shared machine's speed moves all alike.
        pen: dict = {}
        for k in range(a.runs):
            penumbra_run(exe, a.scene, size, k, tmp, pen)
            for n in SAMPLES:
                mits[n].run()
            gl_peer.run()
    load_after = os.getloadavg()[0]
    shadow, gl_receivers = gl_peer.finish()
    gl_times, renderer = gl_peer.times, gl_peer.renderer

    # Receivers: pixels where penumbra's raycast and Mitsuba's primary ray see a surface.
    ref = {n: pen[f"raycast-{n}"]["visibility"] for n in SAMPLES}
    errors_m = {}
    for n in SAMPLES:
        mask = gl_receivers
        errors_m[f"mean |e| vs raycast {n}"] = round(mean_abs(mits[n].image(), ref[n], mask), 5)
    hsv = pen["hard-sv"]["visibility"] < 0.5
    differ = float((hsv != shadow)[gl_receivers].mean())
    gl_vis = (~shadow).astype(np.float64)
    errors_gl = {
        "fraction of receiver pixels differing from hard-sv": round(differ, 5),
        "mean |e| of the lit mask vs raycast 1024": round(mean_abs(gl_vis, ref[1024], gl_receivers), 5),
    }
    hsv_err = round(mean_abs((~hsv).astype(np.float64), ref[1024], gl_receivers), 5)

    hname, htimes = hard_sv_passes(pen["hard-sv"])
    wname, wtimes = wedge_pass(pen["ssv"])
    r16name, r16 = ray_pass(pen["raycast-16"])
    r1kname, r1k = ray_pass(pen["raycast-1024"])
    pen_passes = []
    for key in ("hard-sv", "ssv", "raycast-16", "raycast-1024"):
        entry = pen[key]
        for n in entry["order"]:
            if n != "scene-depth" or key == "hard-sv":
                pen_passes.append(pass_entry(f"{key} {n}", entry["passes"][n]))
        pen_passes.append(pass_entry(f"{key} method total (without scene-depth)", entry["total"]))
    pen_passes.append(pass_entry(f"hard-sv {hname}", htimes))
    pen_errors = {
        "hard-sv lit mask mean |e| vs raycast 1024": hsv_err,
        "raycast 16 mean |e| vs raycast 1024": round(mean_abs(ref[16], ref[1024], gl_receivers), 5),
    }
    m16 = statistics.median(mits[16].times)
    m1k = statistics.median(mits[1024].times)
    gl = statistics.median(gl_times)
    rows = [
        ("`hard-sv` depth + stencil vs llvmpipe warm frame", statistics.median(htimes), gl, 1.0, "≤ 1.0×"),
        ("`raycast` 16 vs Embree 16 (shadow rays)", statistics.median(r16), m16, 2.0, "≤ 2×"),
        ("`ssv` wedge pass vs Embree 16", statistics.median(wtimes), m16, 1.0, "< 1×"),
        ("`raycast` 1024 vs Embree 1024 (shadow rays)", statistics.median(r1k), m1k, 1.2, "≤ 1.2×"),
    ]
    import drjit

    report = {
        "scene": a.scene,
        "options": a.opt,
        "width": w,
        "height": h,
        "runs": a.runs,
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, mitsuba {mi.__version__} "
        f"(drjit {drjit.__version__}, {mi.variant()}), {renderer}; load average "
        f"{load_before:.1f} before, {load_after:.1f} after",
        "triangles": sum(len(m["triangles"]) // 3 for m in doc16["meshes"]),
        "volume_triangles": doc16["hard_sv"]["volume_triangles"],
        "hard_sv_mode": doc16["hard_sv"]["mode"],
        "peers": [
            {
                "name": "penumbra",
                "passes": pen_passes,
                "error": pen_errors,
            },
            {
                "name": "mitsuba-embree",
                "passes": [
                    pass_entry("casters' scene build (Embree BVH)", mits[16].build),
                    *[
                        pass_entry(
                            f"shadow rays, {n} samples ({mits[n].rays} rays)",
                            mits[n].times,
                            f"{errors_m[f'mean |e| vs raycast {n}']}",
                        )
                        for n in SAMPLES
                    ],
                ],
                "error": errors_m,
                "primary_ray_seconds": {str(n): mits[n].primary for n in SAMPLES},
            },
            {
                "name": "llvmpipe",
                "passes": [
                    pass_entry(
                        f"{doc16['hard_sv']['mode']} frame: depth + stencil",
                        gl_times,
                        f"{errors_gl['mean |e| of the lit mask vs raycast 1024']}",
                    )
                ],
                "error": errors_gl,
            },
        ],
        "rows": [
            {"row": r, "penumbra": p, "peer": q, "ratio": p / q, "goal": g, "goal_text": t}
            for r, p, q, g, t in rows
        ],
        "penumbra_passes": {"hard-sv": hname, "ssv": wname, "raycast-16": r16name, "raycast-1024": r1kname},
    }
    write_report(out, report)
    print((out / "peers.md").read_text())
    print(f"peers: {out / 'peers.md'}, {out / 'peers.json'}")
    return 0


def check_doc() -> dict:
    """A 4×4 document with one triangle and no volume: enough to start llvmpipe."""
    return {
        "width": 4,
        "height": 4,
        "meshes": [
            {
                "clip_positions": [-1, -1, 0, 1, 1, -1, 0, 1, 0, 1, 0, 1],
                "triangles": [0, 1, 2],
            }
        ],
        "hard_sv": {"mode": "zfail", "volume_clip": [0.0] * 12},
    }


if __name__ == "__main__":
    sys.exit(main())
