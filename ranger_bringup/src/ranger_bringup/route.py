"""The demo's scripted route and its analysis, free of ROS: which twist to send when, and how far
the driver's odometry drifted from the virtual chassis's ground truth (per segment, per mode).

Poses are (x, y, yaw) in metres and radians; samples are (t, x, y, yaw) with t in seconds.
"""

import math
from dataclasses import dataclass

ACKERMANN, OBLIQUE, SPIN = "ackermann", "oblique", "spin"
MODE_TITLES = {ACKERMANN: "Ackermann", OBLIQUE: "crab (oblique)", SPIN: "spin"}


@dataclass(frozen=True)
class Segment:
    label: str
    mode: str  # the motion mode the twist asks the driver for (ACKERMANN, OBLIQUE, SPIN)
    vx: float = 0.0  # m/s
    vy: float = 0.0  # m/s
    wz: float = 0.0  # rad/s
    duration: float = 1.0  # s of driving, counted once the chassis is in `mode`
    # rad, spins only: the segment turns this far (in wz's direction) by the driver's odometry,
    # slowing down before the end (spin_rate), instead of driving for `duration`, which then
    # bounds how long it may take. 0: driven for `duration`.
    turn: float = 0.0


# About 20 s of driving and five motion-mode switches; the shape (arc, crab, spin) is chosen so
# that each mode moves the robot visibly in the plot.
DEFAULT_ROUTE = (
    Segment("straight ahead", ACKERMANN, vx=0.8, duration=2.5),
    Segment("arc left, radius 2 m", ACKERMANN, vx=0.8, wz=0.4, duration=4.0),
    Segment("crab left", OBLIQUE, vy=0.5, duration=3.0),
    Segment("crab back-right diagonal", OBLIQUE, vx=-0.35, vy=-0.35, duration=3.0),
    Segment("spin left half a turn", SPIN, wz=0.9, duration=10.0, turn=math.pi),
    Segment("arc right, radius 2 m", ACKERMANN, vx=0.8, wz=-0.4, duration=3.0),
)

# A spin by angle (Segment.turn): full rate until the rest of the turn is TURN_GAIN * rate away,
# then the rate in proportion to what is left (never below MIN_SPIN_RATE), done within
# TURN_TOLERANCE. The slowing down keeps what the chassis turns while it brakes small.
TURN_GAIN = 1.0  # 1/s
MIN_SPIN_RATE = 0.15  # rad/s
TURN_TOLERANCE = math.radians(0.5)


def spin_rate(segment, turned):
    """The yaw rate to command in a spin segment with a `turn`, after `turned` rad (signed, in the
    direction of segment.wz) of it; 0.0 once the turn is done."""
    remaining = segment.turn - turned
    if remaining <= TURN_TOLERANCE:
        return 0.0
    rate = min(abs(segment.wz), max(MIN_SPIN_RATE, TURN_GAIN * remaining))
    return math.copysign(rate, segment.wz)


def driving_time(segment):
    """The segment's nominal driving time (s): its duration, or for a turn the turn at its rate."""
    return segment.turn / abs(segment.wz) if segment.turn else segment.duration


def validate_route(route):
    """Raises ValueError naming the first segment whose twist does not ask for its mode."""
    for i, s in enumerate(route):
        where = f"segment {i + 1} ({s.label})"
        if not all(math.isfinite(v) for v in (s.vx, s.vy, s.wz, s.duration)) or s.duration <= 0:
            raise ValueError(f"{where}: velocities must be finite and the duration > 0")
        if s.mode == ACKERMANN and (s.vy != 0 or s.vx == 0):
            raise ValueError(f"{where}: Ackermann needs vx != 0 and vy = 0")
        if s.mode == OBLIQUE and (s.wz != 0 or s.vy == 0):
            raise ValueError(f"{where}: crab needs vy != 0 and wz = 0")
        if s.mode == SPIN and (s.vx != 0 or s.vy != 0 or s.wz == 0):
            raise ValueError(f"{where}: spin needs wz != 0 and no linear velocity")
        if s.turn and (s.mode != SPIN or not math.isfinite(s.turn) or s.turn < 0):
            raise ValueError(f"{where}: a turn is a spin's, finite and >= 0")
        if s.mode not in MODE_TITLES:
            raise ValueError(f"{where}: unknown mode {s.mode!r}")


def mode_switches(route):
    return sum(1 for a, b in zip(route, route[1:]) if a.mode != b.mode)


# ---- planar pose algebra -------------------------------------------------------------------------
def wrap(angle):
    """Angle in [-pi, pi)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


def compose(a, b):
    """a * b: pose b expressed in a's parent frame."""
    ax, ay, ayaw = a
    bx, by, byaw = b
    c, s = math.cos(ayaw), math.sin(ayaw)
    return (ax + c * bx - s * by, ay + s * bx + c * by, wrap(ayaw + byaw))


def inverse(a):
    x, y, yaw = a
    c, s = math.cos(yaw), math.sin(yaw)
    return (-c * x - s * y, s * x - c * y, wrap(-yaw))


def between(a, b):
    """The motion from pose a to pose b, in a's frame: a^-1 * b."""
    return compose(inverse(a), b)


def pose_error(a, b):
    """(position error m, |heading error| rad) between two poses."""
    return math.hypot(a[0] - b[0], a[1] - b[1]), abs(wrap(a[2] - b[2]))


def interpolate(samples, t):
    """Pose at time t from time-sorted samples (linear; clamped at the ends)."""
    if not samples:
        raise ValueError("no samples")
    if t <= samples[0][0]:
        return tuple(samples[0][1:])
    if t >= samples[-1][0]:
        return tuple(samples[-1][1:])
    lo, hi = 0, len(samples) - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if samples[mid][0] <= t:
            lo = mid
        else:
            hi = mid
    t0, x0, y0, yaw0 = samples[lo]
    t1, x1, y1, yaw1 = samples[hi]
    f = (t - t0) / (t1 - t0) if t1 > t0 else 0.0
    return (x0 + f * (x1 - x0), y0 + f * (y1 - y0), wrap(yaw0 + f * wrap(yaw1 - yaw0)))


def rebase(samples, t0):
    """Samples re-expressed relative to the pose at t0 (so odometry and ground truth, whose
    frames may have different origins, start together)."""
    origin_inv = inverse(interpolate(samples, t0))
    return [(t,) + compose(origin_inv, (x, y, yaw)) for t, x, y, yaw in samples]


def path_length(samples, t0=-math.inf, t1=math.inf):
    pts = [s for s in samples if t0 <= s[0] <= t1]
    return sum(math.hypot(b[1] - a[1], b[2] - a[2]) for a, b in zip(pts, pts[1:]))


def rotation(samples, t0=-math.inf, t1=math.inf):
    pts = [s for s in samples if t0 <= s[0] <= t1]
    return sum(abs(wrap(b[3] - a[3])) for a, b in zip(pts, pts[1:]))


def yaw_change(samples, t0=-math.inf, t1=math.inf):
    """The signed yaw turned between t0 and t1 (rad, counter-clockwise positive; several turns
    add up)."""
    pts = [s for s in samples if t0 <= s[0] <= t1]
    return sum(wrap(b[3] - a[3]) for a, b in zip(pts, pts[1:]))


# ---- the analysis --------------------------------------------------------------------------------
@dataclass(frozen=True)
class SegmentResult:
    segment: Segment
    start: float  # s
    end: float  # s
    distance: float  # m travelled (ground truth)
    turned: float  # rad turned (ground truth)
    drift: float  # m: odometry's motion over the segment vs ground truth's
    drift_yaw: float  # rad
    error: float  # m: odometry pose vs ground truth at the segment's end (accumulated)
    error_yaw: float  # rad


def analyse(windows, odom, truth):
    """windows: [(segment, t_start, t_end)]; odom/truth: samples. Returns [SegmentResult] with
    both tracks rebased to their pose at the first window's start."""
    if not windows:
        return []
    t0 = windows[0][1]
    odom, truth = rebase(odom, t0), rebase(truth, t0)
    results = []
    for segment, start, end in windows:
        o0, o1 = interpolate(odom, start), interpolate(odom, end)
        g0, g1 = interpolate(truth, start), interpolate(truth, end)
        drift, drift_yaw = pose_error(between(o0, o1), between(g0, g1))
        error, error_yaw = pose_error(o1, g1)
        results.append(SegmentResult(segment, start, end, path_length(truth, start, end),
                                     rotation(truth, start, end), drift, drift_yaw, error,
                                     error_yaw))
    return results


def _pose_text(metres, radians):
    return f"{metres * 100:6.1f} cm {math.degrees(radians):5.2f} deg"


def summarise(results, odom, truth):
    """The text the demo prints: one row per segment, per-mode totals, the final error."""
    if not results:
        return "no segment was driven"
    t0, t1 = results[0].start, results[-1].end
    odom_r, truth_r = rebase(odom, t0), rebase(truth, t0)
    lines = [f"  {'#':>2}  {'segment':<26} {'mode':<15} {'distance':>8} {'turned':>8}  "
             f"{'odometry drift':>19}  {'pose error at end':>19}"]
    for i, r in enumerate(results, start=1):
        lines.append(f"  {i:>2}  {r.segment.label:<26} {MODE_TITLES[r.segment.mode]:<15} "
                     f"{r.distance:6.2f} m {math.degrees(r.turned):4.0f} deg  "
                     f"{_pose_text(r.drift, r.drift_yaw)}  {_pose_text(r.error, r.error_yaw)}")
    lines.append("  per mode (drift summed over its segments):")
    for mode, title in MODE_TITLES.items():
        rows = [r for r in results if r.segment.mode == mode]
        if not rows:
            continue
        lines.append(f"    {title:<15} {sum(r.distance for r in rows):6.2f} m "
                     f"{math.degrees(sum(r.turned for r in rows)):4.0f} deg  drift "
                     f"{_pose_text(sum(r.drift for r in rows), sum(r.drift_yaw for r in rows))}")
    final_o, final_g = interpolate(odom_r, t1 + 10.0), interpolate(truth_r, t1 + 10.0)
    error, error_yaw = pose_error(final_o, final_g)
    lines.append(f"  total: {path_length(truth_r, t0):.2f} m driven (odometry says "
                 f"{path_length(odom_r, t0):.2f} m); final pose error {error:.3f} m, "
                 f"{math.degrees(error_yaw):.2f} deg")
    return "\n".join(lines)


MODE_COLOURS = {ACKERMANN: "tab:orange", OBLIQUE: "tab:green", SPIN: "tab:purple"}


def plot(results, odom, truth, path, title="RANGER demo: odometry vs ground truth"):
    """Writes a PNG: the ground-truth path (thick, coloured by mode) and the odometry path (thin
    dashed), both rebased to the route's start, with the robot's outline at each segment end."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    t0 = results[0].start if results else (truth[0][0] if truth else 0.0)
    odom_r, truth_r = rebase(odom, t0), rebase(truth, t0)
    fig, ax = plt.subplots(figsize=(8, 7), dpi=110)
    ax.plot([s[1] for s in truth_r], [s[2] for s in truth_r], color="0.8", lw=6, zorder=1)
    for i, r in enumerate(results, start=1):
        colour = MODE_COLOURS[r.segment.mode]
        pts = [s for s in truth_r if r.start <= s[0] <= r.end]
        ax.plot([s[1] for s in pts], [s[2] for s in pts], color=colour, lw=4, zorder=2,
                solid_capstyle="round")
        x, y, yaw = interpolate(truth_r, r.end)
        _outline(ax, (x, y, yaw), colour)
        # The segment's number (as in the summary) halfway along it; a spin stays in place,
        # so its number sits on the spot.
        mx, my, _ = interpolate(truth_r, (r.start + r.end) / 2)
        ax.annotate(str(i), (mx, my), xytext=(9, 9), textcoords="offset points", fontsize=9,
                    color="white", weight="bold", zorder=5,
                    bbox=dict(boxstyle="circle,pad=0.25", fc=colour, ec="none"))
    ax.plot([s[1] for s in odom_r], [s[2] for s in odom_r], color="black", lw=1.2, ls="--",
            zorder=3)
    ax.plot([0], [0], "ko", zorder=4)
    handles = [Line2D([], [], color=c, lw=4, label=f"ground truth, {MODE_TITLES[m]}")
               for m, c in MODE_COLOURS.items()]
    handles.append(Line2D([], [], color="black", lw=1.2, ls="--", label="driver odometry"))
    ax.legend(handles=handles, loc="best", fontsize=9)
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.4)
    ax.set_xlabel("x (m, odom frame at start)")
    ax.set_ylabel("y (m)")
    if results:
        final = pose_error(interpolate(odom_r, results[-1].end + 10),
                           interpolate(truth_r, results[-1].end + 10))
        title += f"\nfinal error {final[0] * 100:.1f} cm, {math.degrees(final[1]):.2f} deg"
    ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def _outline(ax, pose, colour, length=1.228, width=0.876):
    x, y, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    corners = [(length / 2, width / 2), (-length / 2, width / 2), (-length / 2, -width / 2),
               (length / 2, -width / 2), (length / 2, width / 2)]
    xs = [x + c * a - s * b for a, b in corners]
    ys = [y + s * a + c * b for a, b in corners]
    ax.plot(xs, ys, color=colour, lw=1, alpha=0.7, zorder=2)
    ax.plot([x, x + c * length / 2], [y, y + s * length / 2], color=colour, lw=1, alpha=0.7)
