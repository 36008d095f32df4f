#!/usr/bin/env python3
"""Writes the fuzz seed corpora (fuzz/seeds/TARGET/*): one input per extreme class, in the
byte encoding of fuzz/src/lib.rs (a selector byte 0 then the f32 bits, little-endian).
Run from the repository root: python3 scripts/make_seeds.py"""
import math
import pathlib
import struct

MAX = 3.4028234663852886e38
INF = float("inf")
NAN = float("nan")
TINY = 1.401298464324817e-45  # 2^-149


def f(x):
    return b"\x00" + struct.pack("<f", x)


def problem3(cols, t, lo, hi, order=1):
    return b"".join(f(x) for c in cols for x in c) + b"".join(map(f, t + lo + hi)) + bytes([order])


def problem2(cols, t, lo, hi, order=1):
    return b"".join(f(x) for c in cols for x in c) + b"".join(map(f, t + lo + hi)) + bytes([order])


def rot3(a, noise=0.0):
    c, s = math.cos(a), math.sin(a)
    return [[c, s + noise, noise], [-s, c, noise], [noise, 0.0, 1.0]]


I3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
classes3 = {
    "far_1e3": (rot3(0.3), [1e3, -1e3, 1e3], [-0.01] * 3, [0.01] * 3),
    "far_1e5": (rot3(0.3), [1e5, -1e5, 1e5], [-0.01] * 3, [0.01] * 3),
    "far_1e7": (rot3(0.3), [1e7, -1e7, 1e7], [-0.01] * 3, [0.01] * 3),
    "far_1e9": (rot3(0.3), [1e9, -1e9, 1e9], [-0.01] * 3, [0.01] * 3),
    "near_max": (rot3(0.7), [0.0] * 3, [-3e38] * 3, [3e38] * 3),
    "overflow": ([[10.0, 0, 0], [0, 10.0, 0], [0, 0, 10.0]], [0.0] * 3, [1e38] * 3, [2e38] * 3),
    "subnormal": ([[TINY, 0, 0], [0, 1.0, 0], [0, 0, 1e30]], [TINY] * 3, [TINY] * 3, [3 * TINY] * 3),
    "zero_size": (rot3(1.1), [1.0, 2.0, 3.0], [0.5] * 3, [0.5] * 3),
    "signed_zero": ([[-0.0, 0.0, 1.0], [0.0, -0.0, 0.0], [1.0, 0.0, -0.0]], [-0.0, 0.0, -0.0], [-0.0] * 3, [0.0] * 3),
    "quarter_turn": (rot3(math.pi / 2, 1e-7), [0.0] * 3, [-1.0] * 3, [1.0] * 3),
    "drifted": ([[x * 1.001 for x in c] for c in rot3(0.4)], [1.0] * 3, [-1.0] * 3, [1.0] * 3),
    "reflection": ([[-1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]], [0.0] * 3, [-1.0, 0.0, 1.0], [2.0, 1.0, 3.0]),
    "near_singular": ([[1e-7, 0, 0], [0, 1e7, 0], [0, 0, 0.0]], [0.0] * 3, [-1.0] * 3, [1.0] * 3),
    "shear": ([[1.0, 0, 0], [5.0, 1.0, 0], [0, -3.0, 1.0]], [0.0] * 3, [-1.0] * 3, [1.0] * 3),
    "unbounded": (I3, [1.0, 2.0, 3.0], [-INF, 0.0, 0.0], [INF, 1.0, 1.0]),
    "empty": (rot3(0.2), [0.0] * 3, [INF] * 3, [-INF] * 3),
    "nan": (rot3(0.2), [NAN, 0.0, 0.0], [0.0] * 3, [1.0] * 3),
}

H = math.sqrt(0.5)
UNIT = [0.1, 0.2, 0.3, math.sqrt(1 - 0.14)]
# Per extreme class: a quaternion [x, y, z, w] and a per-axis scale.
QUATS = {
    "far_1e3": (UNIT, [1.0] * 3),
    "far_1e5": (UNIT, [2.0] * 3),
    "far_1e7": (UNIT, [1.0, 2.0, 3.0]),
    "far_1e9": (UNIT, [1.0] * 3),
    "near_max": ([1e19, 2e18, 0.0, 1.0], [1e38, 1.0, 2.0]),
    "overflow": ([0.0, 0.0, 0.0, 1.0], [3e38] * 3),
    "subnormal": ([TINY, 0.0, TINY, 1.0], [TINY, 1.0, 1e30]),
    "zero_size": (UNIT, [1.0] * 3),
    "signed_zero": ([-0.0, 0.0, -0.0, 1.0], [-0.0, 0.0, 1.0]),
    "quarter_turn": ([0.0, 0.0, H, H], [1.0] * 3),
    "drifted": ([x * 1.001 for x in UNIT], [1.0] * 3),
    "reflection": (UNIT, [-1.0, 1.0, -2.0]),
    "near_singular": ([0.0] * 4, [0.0, 1e-30, 1e30]),
    "shear": ([3.0, -2.0, 5.0, 0.5], [1.0] * 3),
    "unbounded": ([0.0, 0.0, 0.0, 1.0], [1.0, 0.0, 2.0]),
    "empty": (UNIT, [1.0] * 3),
    "nan": ([NAN, 0.0, 0.0, 1.0], [1.0] * 3),
}

root = pathlib.Path("fuzz/seeds")
TARGETS = ["affine3", "affine2", "rigid2", "mat4", "batch", "translation3", "translation2",
           "rigid3", "similarity3", "trs3", "update"]
for target in TARGETS:
    (root / target).mkdir(parents=True, exist_ok=True)

for name, (cols, t, lo, hi) in classes3.items():
    order = 0 if name == "empty" else 1  # 0 keeps min > max as given
    data3 = problem3(cols, t, lo, hi, order)
    (root / "affine3" / name).write_bytes(data3)
    cols2 = [c[:2] for c in cols[:2]]
    data2 = problem2(cols2, t[:2], lo[:2], hi[:2], order)
    (root / "affine2" / name).write_bytes(data2)
    (root / "rigid2" / name).write_bytes(data2)
    # Translations read a whole problem and keep its translation and box.
    (root / "translation3" / name).write_bytes(data3)
    (root / "translation2" / name).write_bytes(data2)
    # Quaternion classes: the problem, then the quaternion, then the scale (1 or 3 floats).
    q, scale = QUATS[name]
    quat = b"".join(map(f, q))
    (root / "rigid3" / name).write_bytes(data3 + quat)
    (root / "similarity3" / name).write_bytes(data3 + quat + f(scale[0]))
    (root / "trs3" / name).write_bytes(data3 + quat + b"".join(map(f, scale)))
    # update: the problem and quaternion (current pose), the same again (predicted: a
    # typical quaternion), then a fat box and a margin: a fat box around the origin and
    # the margin (0.1, 0.5).
    typical = b"".join(map(f, UNIT))
    fat = b"".join(map(f, [-1.0, -1.0, -1.0, 1.0, 1.0, 1.0]))
    (root / "update" / name).write_bytes(data3 + quat + data3 + typical + fat + f(0.1) + f(0.5))
    # batch: backend, method, rounding, class, n bytes, then n problems of the class
    # (0 affine, 2 rigid3, 5 affine 2D).
    (root / "batch" / name).write_bytes(bytes([0, 1, 1, 0, 9]) + data3 * 9)
    (root / "batch" / (name + "_rigid3")).write_bytes(bytes([1, 2, 1, 2, 9]) + (data3 + quat) * 9)
    (root / "batch" / (name + "_2d")).write_bytes(bytes([2, 0, 0, 5, 9]) + data2 * 9)

# mat4: 16 column-major entries, the "make affine" byte, then the box.
def mat4(cols, lo, hi, make_affine):
    return b"".join(f(x) for c in cols for x in c) + bytes([make_affine]) + b"".join(map(f, lo + hi))


perspective = [[1.0, 0, 0, 0], [0, 1.5, 0, 0], [0, 0, -1.0, -1.0], [0, 0, -0.1, 0.0]]
(root / "mat4" / "projective_in_front").write_bytes(mat4(perspective, [-1.0, -1.0, -5.0], [1.0, 1.0, -2.0], 1))
(root / "mat4" / "projective_behind_eye").write_bytes(mat4(perspective, [-1.0, -1.0, -5.0], [1.0, 1.0, 1.0], 1))
(root / "mat4" / "non_affine_row").write_bytes(mat4([[1.0, 0, 0, 0.5], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], [0.0] * 3, [1.0] * 3, 1))
(root / "mat4" / "affine").write_bytes(mat4([[0.0, 1, 0, 0], [-1, 0, 0, 0], [0, 0, 1, 0], [5, 6, 7, 1]], [-1.0] * 3, [1.0] * 3, 0))
(root / "mat4" / "nan_entry").write_bytes(mat4([[NAN, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], [0.0] * 3, [1.0] * 3, 0))
(root / "mat4" / "unbounded_projective").write_bytes(mat4(perspective, [-1.0, -1.0, -INF], [1.0, 1.0, -1.0], 1))
print("seeds written under", root)

# fit: a choice byte (mode = choice % 3; box, sphere, capsule, from_axes = choice / 3 % 4),
# the point count, the points; for from_axes a rotation (selector 0, a quaternion); then a
# probe point, a probe kind (0 box, 1 sphere, 2 capsule) and that volume's raw fields.
TILT = [0.2, -0.3, 0.1, math.sqrt(1 - 0.14)]
FIT_CLASSES = {
    "typical": [[0.0, 0.0, 0.0], [1.0, 0.2, -0.5], [0.3, 2.0, 0.1], [-0.4, 0.5, 1.5], [0.7, -1.0, 0.9]],
    "flat_parallel": [[1e-30, 2e-30, 0.0], [1e30, 1e30, 0.0], [-1e30, -1e30, 0.0]],
    "near_max": [[MAX, MAX, 0.0], [MAX / 2, MAX, MAX * 0.75], [MAX, MAX / 2, MAX]],
    "spread_max": [[-MAX, -MAX, -MAX], [MAX, MAX, MAX], [MAX, -MAX, 0.0]],
    "subnormal": [[TINY, 0.0, 0.0], [0.0, 3 * TINY, 0.0], [0.0, 0.0, 2 * TINY], [TINY, TINY, TINY]],
    "far_1e9": [[1e9, 1e9, -1e9], [1e9 + 64, 1e9, -1e9], [1e9, 1e9 + 128, -1e9 + 64]],
    "collinear": [[0.0, 0.0, 0.0], [1.0, 2.0, 3.0], [-2.0, -4.0, -6.0], [0.5, 1.0, 1.5]],
    "one_point": [[1.5, -2.25, 1e-3]],
    "duplicates": [[1.0, 2.0, 3.0]] * 3 + [[-1.0, 0.0, 1.0]] * 2,
    "signed_zero": [[-0.0, 0.0, -0.0], [0.0, -0.0, 0.0], [1.0, -0.0, 0.0]],
    "nan": [[0.0, 0.0, 0.0], [1.0, NAN, 0.0]],
    "inf": [[0.0, INF, 0.0], [1.0, 1.0, 1.0]],
    "empty": [],
}
(root / "fit").mkdir(parents=True, exist_ok=True)
for c, (name, points) in enumerate(FIT_CLASSES.items()):
    for kind in range(4):
        choice = kind * 3 + (c + kind) % 3
        body = bytes([choice, len(points)]) + b"".join(f(x) for p in points for x in p)
        if kind == 3:
            body += bytes([0]) + b"".join(map(f, TILT))
        probe = b"".join(map(f, [0.5, 0.25, -0.5]))
        volume = [
            bytes([0]) + b"".join(map(f, [0.0, 0.0, 0.0, 1.0, 1.0, 1.0])) + bytes([0]) + b"".join(map(f, TILT)),
            bytes([1]) + b"".join(map(f, [0.0, 0.0, 0.0, 1.0])),
            bytes([2]) + b"".join(map(f, [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.5])),
        ][kind % 3]
        (root / "fit" / f"{name}_{kind}").write_bytes(body + probe + volume)

# volume_world: a class byte (translation, rigid, similarity, trs, affine; 5 = images under a
# similarity), a kind byte (box, sphere, capsule), the class's problem, then the volume's
# raw fields from the problem's box (a box also takes a rotation: selector 0, a quaternion).
(root / "volume_world").mkdir(parents=True, exist_ok=True)
for name, (cols, t, lo, hi) in classes3.items():
    order = 0 if name == "empty" else 1
    data3 = problem3(cols, t, lo, hi, order)
    q, scale = QUATS[name]
    quat = b"".join(map(f, q))
    half = [(h - l) / 2 if math.isfinite(h - l) else h for l, h in zip(lo, hi)]
    fields = [
        b"".join(map(f, lo + half)) + bytes([0]) + b"".join(map(f, TILT)),
        b"".join(map(f, hi + [half[0]])),
        b"".join(map(f, lo + hi + [half[1]])),
    ]
    problems = [data3, data3 + quat, data3 + quat + f(scale[0]), data3 + quat + b"".join(map(f, scale)), data3]
    for k in range(3):
        cls = (k + len(name)) % 5
        (root / "volume_world" / f"{name}_{k}").write_bytes(bytes([cls, k]) + problems[cls] + fields[k])
    images = data3 + quat + f(scale[0]) + b"".join(fields)
    (root / "volume_world" / f"{name}_images").write_bytes(bytes([5, 1]) + images)
