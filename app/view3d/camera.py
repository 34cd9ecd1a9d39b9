"""An orbit camera for the 3D view: projection of Nx3 arrays to the screen, picking, preset
views and fit-all. Z is up (the robot's base frame); screen y grows downwards.

The camera looks at ``target`` from ``distance`` along the direction given by ``yaw`` (about
Z, from +X) and ``pitch`` (elevation above the XY plane). Projection is one matrix product for
any number of points; points behind the eye come back as NaN.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field, replace
from typing import Final

import numpy as np
from numpy.typing import NDArray

from app.errors import InvalidInput

FloatArray = NDArray[np.float64]

FOV_DEG: Final = 40.0  # vertical field of view
NEAR_MM: Final = 10.0  # points closer to the eye than this are not drawn
MIN_DISTANCE: Final = 50.0
MAX_DISTANCE: Final = 100_000.0
MAX_PITCH: Final = 90.0
FIT_MARGIN: Final = 1.1  # the fitted scene fills 1/1.1 of the viewport's tighter side
FIT_MIN_HALF_MM: Final = 50.0  # a single point is framed 100 mm across
PICK_RADIUS_PX: Final = 8.0


class Preset(enum.Enum):
    TOP = "top"  # looking down, X right, Y up (as the planner's top projection)
    FRONT = "front"  # from -Y: X right, Z up (the planner's front projection)
    SIDE = "side"  # from +X: Y right, Z up (the planner's side projection)
    ISO = "iso"


PRESET_ANGLES: Final[dict[Preset, tuple[float, float]]] = {
    Preset.TOP: (-90.0, 90.0),
    Preset.FRONT: (-90.0, 0.0),
    Preset.SIDE: (0.0, 0.0),
    Preset.ISO: (-55.0, 28.0),
}


@dataclass(frozen=True)
class Camera:
    yaw: float = -55.0  # degrees
    pitch: float = 28.0  # degrees
    distance: float = 2600.0  # mm from the target
    target: tuple[float, float, float] = (250.0, 0.0, 400.0)
    ortho: bool = False
    fov: float = FOV_DEG
    _basis: FloatArray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        for name in ("yaw", "pitch", "distance", "fov"):
            if not math.isfinite(getattr(self, name)):
                raise InvalidInput(f"camera {name} must be a finite number")
        object.__setattr__(self, "pitch", max(-MAX_PITCH, min(MAX_PITCH, self.pitch)))
        object.__setattr__(self, "distance", max(MIN_DISTANCE, min(MAX_DISTANCE, self.distance)))
        y, p = math.radians(self.yaw), math.radians(self.pitch)
        back = np.array([math.cos(p) * math.cos(y), math.cos(p) * math.sin(y), math.sin(p)])
        right = np.array([-math.sin(y), math.cos(y), 0.0])
        forward = -back
        up = np.cross(right, forward)
        object.__setattr__(self, "_basis", np.stack([right, up, forward]))  # rows: camera axes

    @property
    def eye(self) -> FloatArray:
        eye = np.asarray(self.target, dtype=np.float64) - self._basis[2] * self.distance
        return np.asarray(eye, dtype=np.float64)

    @property
    def basis(self) -> FloatArray:
        """(3, 3) rows: screen right, screen up, viewing direction (world)."""
        return np.asarray(self._basis, dtype=np.float64)

    def focal(self, height: int) -> float:
        """Pixels per mm at unit depth (perspective) — or per mm (ortho, at the target)."""
        f = (max(1, height) / 2.0) / math.tan(math.radians(self.fov) / 2.0)
        return f / self.distance if self.ortho else f

    def to_camera(self, xyz: FloatArray) -> FloatArray:
        """(n, 3) camera coordinates: right, up, depth (mm)."""
        pts = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
        return np.asarray((pts - self.eye) @ self._basis.T, dtype=np.float64)

    def project(self, xyz: FloatArray, width: int, height: int) -> tuple[FloatArray, FloatArray]:
        """Screen positions (n, 2) in pixels and depths (n,); NaN behind the eye."""
        cam = self.to_camera(xyz)
        depth = cam[:, 2]
        f = self.focal(height)
        if self.ortho:
            scale = np.full(depth.shape, f)
        else:
            with np.errstate(divide="ignore", invalid="ignore"):
                scale = np.where(depth > NEAR_MM, f / depth, np.nan)
        screen = np.empty((cam.shape[0], 2))
        screen[:, 0] = width / 2.0 + cam[:, 0] * scale
        screen[:, 1] = height / 2.0 - cam[:, 1] * scale
        return screen, depth

    def pixels_per_mm(self, height: int) -> float:
        """Scale at the target's depth (for the grid's scale label and level of detail)."""
        f = self.focal(height)
        return f if self.ortho else f / self.distance

    # --- moves ---------------------------------------------------------------------------
    def orbited(self, d_yaw: float, d_pitch: float) -> Camera:
        return replace(self, yaw=(self.yaw + d_yaw + 180.0) % 360.0 - 180.0, pitch=self.pitch + d_pitch)

    def zoomed(self, factor: float) -> Camera:
        if not (math.isfinite(factor) and factor > 0):
            raise InvalidInput("zoom factor must be > 0")
        return replace(self, distance=self.distance / factor)

    def panned(self, dx_px: float, dy_px: float, height: int) -> Camera:
        """Move the target so the scene follows the mouse by (dx, dy) pixels."""
        mm = 1.0 / self.pixels_per_mm(height)
        delta = (-dx_px * self._basis[0] + dy_px * self._basis[1]) * mm
        t = np.asarray(self.target) + delta
        return replace(self, target=(float(t[0]), float(t[1]), float(t[2])))

    def preset(self, which: Preset) -> Camera:
        yaw, pitch = PRESET_ANGLES[which]
        return replace(self, yaw=yaw, pitch=pitch)

    def pixels_per_mm_at(self, xyz: FloatArray, height: int) -> float:
        """Scale at the depth of ``xyz`` (one point): what keeps a marker's screen size."""
        if self.ortho:
            return self.pixels_per_mm(height)
        depth = float(self.to_camera(xyz)[0, 2])
        return self.focal(height) / max(depth, NEAR_MM)

    def point_at(self, sx: float, sy: float, width: int, height: int) -> FloatArray:
        """The world point under the screen position (sx, sy) on the plane through the target
        that faces the camera (inverse of :meth:`project` at the target's depth)."""
        ppm = self.pixels_per_mm(height)
        right, up = (sx - width / 2.0) / ppm, (height / 2.0 - sy) / ppm
        point = np.asarray(self.target, dtype=np.float64) + right * self._basis[0] + up * self._basis[1]
        return np.asarray(point, dtype=np.float64)

    def zoomed_at(self, factor: float, sx: float, sy: float, width: int, height: int) -> Camera:
        """Zoomed by ``factor`` about the screen position (sx, sy): the eye moves along the ray
        through it, so every world point on that ray stays under (sx, sy) (perspective and
        orthographic alike; the distance's limits shorten the step, never shift the point)."""
        zoomed = self.zoomed(factor)
        k = self.distance / zoomed.distance  # the factor left after the distance's limits
        anchor = self.point_at(sx, sy, width, height)
        target = np.asarray(self.target, dtype=np.float64)
        moved = target + (anchor - target) * (1.0 - 1.0 / k)
        return replace(zoomed, target=(float(moved[0]), float(moved[1]), float(moved[2])))

    def fitted(self, xyz: FloatArray, aspect: float = 1.0, margin: float = FIT_MARGIN) -> Camera:
        """Framing the finite points of ``xyz`` as tightly as the viewport (width / height
        ``aspect``) allows with ``margin`` to spare, the direction of view kept.

        In the camera's axes (right r, up u, depth f) a point is inside the horizontal field of
        an eye at (e_r, e_f) when |r - e_r| <= (f - e_f) * tan: the two sides' supporting planes
        (the extreme r + f*tan and r - f*tan over the points) give the eye's r and the farthest
        depth it may stand at, the same for up; the eye takes the farther of the two depths.
        Orthographic: the points' extents across the view. The target is where the view's axis
        crosses the depth of the points' bounding box centre. A point, a line or a flat scene is
        framed at least 100 mm across along its thin axes."""
        pts = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
        pts = pts[np.isfinite(pts).all(axis=1)]
        if not len(pts):
            return self
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        centre = (lo + hi) / 2.0
        thin = np.flatnonzero((hi - lo) / 2.0 < FIT_MIN_HALF_MM)  # a point, a line, a flat scene
        if len(thin):
            pad = np.eye(3)[thin] * FIT_MIN_HALF_MM
            pts = np.vstack([pts, centre + pad, centre - pad])
        rel = (pts - centre) @ self._basis.T  # right, up, depth from the centre
        tan_v = math.tan(math.radians(self.fov) / 2.0) / margin
        tan_h = tan_v * max(aspect, 1e-3)
        r, u, f = rel[:, 0], rel[:, 1], rel[:, 2]
        depth = 0.0  # the target's, from the centre
        if self.ortho:
            eye_r, eye_u = (r.max() + r.min()) / 2.0, (u.max() + u.min()) / 2.0
            distance = max((r.max() - r.min()) / 2.0 / tan_h, (u.max() - u.min()) / 2.0 / tan_v)
        else:
            a, b = (r + f * tan_h).min(), (r - f * tan_h).max()
            c, d = (u + f * tan_v).min(), (u - f * tan_v).max()
            eye_r, eye_u = (a + b) / 2.0, (c + d) / 2.0
            eye_f = min((a - b) / (2.0 * tan_h), (c - d) / (2.0 * tan_v), f.min() - 2.0 * NEAR_MM)
            distance = max(-eye_f, MIN_DISTANCE)  # the eye stays where it must be
            depth = eye_f + distance
        t = centre + eye_r * self._basis[0] + eye_u * self._basis[1] + depth * self._basis[2]
        return replace(self, target=(float(t[0]), float(t[1]), float(t[2])), distance=float(distance))


def pick(
    screen: FloatArray,
    pos: tuple[float, float],
    radius: float = PICK_RADIUS_PX,
    depth: FloatArray | None = None,
) -> int | None:
    """Index of the marker nearest ``pos`` within ``radius`` pixels (the nearer to the eye on
    a tie within a pixel), or None."""
    if not len(screen):
        return None
    d = np.hypot(screen[:, 0] - pos[0], screen[:, 1] - pos[1])
    d = np.where(np.isfinite(d), d, np.inf)
    best = float(d.min())
    if best > radius:
        return None
    near = np.flatnonzero(d <= best + 1.0)
    if depth is not None and len(near) > 1:
        return int(near[int(np.argmin(depth[near]))])
    return int(np.argmin(d))


def grid_lines(extent: float, step: float, z: float = 0.0) -> FloatArray:
    """(k, 2, 3) floor grid lines over [-extent, extent] in X and Y."""
    if not (step > 0 and extent > 0):
        raise InvalidInput("grid step and extent must be > 0")
    ticks = np.arange(-extent, extent + step / 2.0, step)
    n = len(ticks)
    lines = np.empty((2 * n, 2, 3))
    lines[:n, 0] = np.stack([ticks, np.full(n, -extent), np.full(n, z)], axis=1)
    lines[:n, 1] = np.stack([ticks, np.full(n, extent), np.full(n, z)], axis=1)
    lines[n:, 0] = np.stack([np.full(n, -extent), ticks, np.full(n, z)], axis=1)
    lines[n:, 1] = np.stack([np.full(n, extent), ticks, np.full(n, z)], axis=1)
    return lines


def nice_step(mm: float) -> float:
    """1, 2 or 5 times a power of ten, at least ``mm``."""
    if not mm > 0:
        return 1.0
    exp = math.floor(math.log10(mm))
    for m in (1.0, 2.0, 5.0, 10.0):
        if m * 10.0**exp >= mm:
            return m * 10.0**exp
    return 10.0 ** (exp + 1)
