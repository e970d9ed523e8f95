"""Routes round obstacles and inside a boundary, against closed-form paths.

A reach at constant boat speed blocked by a rectangle: the fastest route is the
shortest path round the rectangle's corners, so its time is that length over the speed.
A beat up a channel: boards at the VMG angle cross the channel, so the number of tacks
follows from the channel's width, its length and the VMG angle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest
import shapely

from sailroute.boat.polar import Polar
from sailroute.errors import InputError, RoutingError
from sailroute.routing.api import ROUTERS, check_router_supports, route_leg
from sailroute.routing.griddp import route_griddp
from sailroute.routing.isochrone import route_isochrone
from sailroute.routing.obstacles import (
    BOUNDARY_NAME,
    CORE_M,
    QUAD_SEGS,
    AreaPolygon,
    Obstacles,
    RaceArea,
    land_obstacle,
    obstacles_for,
)
from sailroute.routing.settings import RoutingSettings, routing_settings
from sailroute.routing.types import LegResult, Start, Target
from sailroute.wind.uniform import UniformWind
from tests.routing.polars import laser_like_polar

T0 = 1_524_567_600.0
SPEED = 5.0  # boat speed of the constant polar [m/s]


def constant_polar() -> Polar:
    """5 m/s at every TWA from 40° to 180° (flat nodes: PCHIP keeps it flat)."""
    twa = np.array([0, 30, 40, 60, 90, 120, 150, 180.0])
    g = np.array([0, 0.5, 1, 1, 1, 1, 1, 1.0])
    tws = np.array([2, 6, 10.0])
    return Polar.from_arrays(twa, tws, np.outer(g, np.full(3, SPEED)), name="constant")


def rect(
    name: str, x0: float, x1: float, y0: float, y1: float, clearance: float = 0.0
) -> AreaPolygon:
    return AreaPolygon(name, (x0, x1, x1, x0), (y0, y0, y1, y1), clearance)


# the blocked reach: wind from the west, course north from (0, 0) to a short line at
# y = 2000; a 800 m x 600 m block across the direct path, nearer its left (west) corners
BLOCK = rect("block", -300.0, 500.0, 700.0, 1300.0)
REACH = (
    Start((0.0, 0.0), name="start"),
    Target("line", (-50.0, 2000.0), (50.0, 2000.0), name="finish"),
)
REACH_WIND = UniformWind(6.0, 270.0)
# shortest path: start -> (-300, 700) -> (-300, 1300) -> line end (-50, 2000)
REACH_LENGTH = math.hypot(300, 700) + 600 + math.hypot(250, 700)


def reach_settings(router: str = "isochrone") -> RoutingSettings:
    return routing_settings(
        router=router,
        dt_s=5.0,
        tack_penalty_s=0.0,
        gybe_penalty_s=0.0,
        heading_step_deg=1.0,
        dp_half_width_m=600.0,
        dp_cols=96,
        dp_rows=17,
        dp_refinements=3,
    )


def track_free(res: LegResult, obs: Obstacles) -> bool:
    x, y = res.track.x, res.track.y
    return bool(np.all(obs.segments_free(x[:-1], y[:-1], x[1:], y[1:])))


# ---------------------------------------------------------------------- predicates
def test_points_and_segments_free_by_hand() -> None:
    obs = Obstacles.build(
        RaceArea(rect("bound", -100, 100, -100, 100), (rect("b", -10, 10, -10, 10),))
    )
    assert obs is not None
    assert obs.points_free([0, 50, 150, 10], [0, 50, 0, 0]).tolist() == [False, True, False, False]
    # through the block, round it, out of the boundary, through a corner exactly
    free = obs.segments_free(
        [-50, -50, 0, -50], [0, 20, 50, 50], [50, 50, 0, 50], [0, 20, 150, -50]
    )
    assert free.tolist() == [False, True, False, False]


def test_edge_test_agrees_with_shapely_linestrings() -> None:
    area = RaceArea(
        rect("bound", -500, 500, -500, 500, clearance=20.0),
        tuple(
            rect(f"o{k}", -400 + 80 * k, -350 + 80 * k, -100, 60 + 10 * k, 5.0) for k in range(10)
        ),
    )
    obs = Obstacles.build(area)
    assert obs is not None
    rng = np.random.default_rng(1)
    x0, y0 = rng.uniform(-550, 550, (2, 20000))
    ang, length = rng.uniform(0, 2 * np.pi, 20000), rng.uniform(0, 120, 20000)
    x1, y1 = x0 + length * np.sin(ang), y0 + length * np.cos(ang)
    ours = obs.segments_free(x0, y0, x1, y1)
    theirs = obs.segments_free_shapely(x0, y0, x1, y1)
    assert 0.2 < ours.mean() < 0.9  # both outcomes are exercised
    assert np.array_equal(ours, theirs)
    # the fan form (rows decided by their start when no edge is within reach) agrees too
    px, py = x0[:200], y0[:200]
    qx, qy = (
        x1[: 200 * 100].reshape(200, 100) - x0[: 200 * 100].reshape(200, 100) + px[:, None],
        y1[: 200 * 100].reshape(200, 100) - y0[: 200 * 100].reshape(200, 100) + py[:, None],
    )
    assert np.array_equal(
        obs.moves_free(px, py, qx, qy), obs.segments_free(px[:, None], py[:, None], qx, qy)
    )


def test_fan_in_a_rotated_frame_agrees_with_the_segment_test() -> None:
    # the isochrone's form: fans in its leg frame (rotated and shifted), only the tested
    # ends moved to the course frame; obstacles of 4 to 70 edges (groups of 32 and a
    # rest, padded), a boundary with clearance, moves of every length from none to
    # several edges' widths; the answer is the course-frame segment test move by move
    disc = AreaPolygon(
        "disc",
        tuple(120 + 60 * np.cos(np.linspace(0, 2 * np.pi, 70, endpoint=False))),
        tuple(-80 + 60 * np.sin(np.linspace(0, 2 * np.pi, 70, endpoint=False))),
        4.0,
    )
    tri = AreaPolygon("tri", (-200.0, -120.0, -160.0), (150.0, 150.0, 260.0))
    area = RaceArea(
        rect("bound", -400, 400, -300, 300, clearance=15.0),
        (disc, tri, rect("pier", 0, 10, 0, 200), rect("box", -300, -250, -200, -120, 8.0)),
    )
    obs = Obstacles.build(area)
    assert obs is not None
    assert obs.group_edges.shape[1] == 32 and obs.group_box.shape[0] > 8
    ang = math.radians(37.0)
    fx, fy, cx, cy = math.sin(ang), math.cos(ang), 35.0, -20.0

    def to_world(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return cx + x * fy + y * fx, cy - x * fx + y * fy

    rng = np.random.default_rng(5)
    n, m = 400, 60
    px, py = rng.uniform(-450, 450, n), rng.uniform(-450, 450, n)
    length = rng.uniform(0, 120, (n, m)) * (rng.uniform(size=(n, m)) > 0.05)
    heading = rng.uniform(0, 2 * np.pi, (n, m))
    qx, qy = px[:, None] + length * np.sin(heading), py[:, None] + length * np.cos(heading)
    ours = obs.moves_free(px, py, qx, qy, to_world)
    wx, wy = to_world(px, py)
    theirs = obs.segments_free(wx[:, None], wy[:, None], *to_world(qx, qy))
    assert 0.2 < ours.mean() < 0.9  # both outcomes are exercised
    assert np.array_equal(ours, theirs)
    # the moves that end in the core of the blocked water (blocked without the edge
    # test) are among them; the obstacles' core boxes lie CORE_M or more inside them
    ex, ey = to_world(qx, qy)
    cores = obs.core_box[~obs.core_outer]
    in_core = np.zeros(ex.shape, dtype=bool)
    grown = [
        shapely.buffer(o.polygon(), o.clearance_m, quad_segs=QUAD_SEGS) for o in area.obstacles
    ]
    for b in cores[np.isfinite(cores[:, 0])]:
        core = shapely.box(*b)
        assert any(shapely.contains(shapely.buffer(g, -CORE_M), core) for g in grown)
        in_core |= (ex >= b[0]) & (ex <= b[2]) & (ey >= b[1]) & (ey <= b[3])
    assert in_core.sum() > 100 and not np.any(theirs[in_core])
    # and in the course frame, with the shapely linestrings for a second opinion
    assert np.array_equal(obs.moves_free(wx, wy, *to_world(qx, qy)), theirs)
    free = obs.segments_free_shapely(wx[:, None], wy[:, None], *to_world(qx, qy))
    assert np.mean(free == theirs) > 0.999  # the same up to touching


@dataclass(frozen=True)
class _Frame:
    """A rotated, shifted frame whose bound ``to_world`` the move test may cache by."""

    deg: float
    cx: float
    cy: float

    def to_world(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        fx, fy = math.sin(math.radians(self.deg)), math.cos(math.radians(self.deg))
        return self.cx + x * fy + y * fx, self.cy - x * fx + y * fy


def test_the_isochrone_shortcuts_give_the_segment_test_answers() -> None:
    # the isochrone's calls: starts known free (a front after the first), the rows'
    # reach bound instead of their ends' box, a whole front far from every edge skipped,
    # and two frames in turn (the groups' boxes kept for the last one): the same answers
    # as the course-frame segment test, move by move
    area = RaceArea(
        rect("bound", -400, 400, -300, 300, clearance=15.0),
        (rect("pier", 0, 10, 0, 200), rect("box", -300, -250, -200, -120, 8.0)),
    )
    obs = Obstacles.build(area)
    assert obs is not None
    rng = np.random.default_rng(11)
    n, m = 300, 40
    for frame in (_Frame(37.0, 35.0, -20.0), _Frame(-120.0, -60.0, 15.0)) * 2:
        px, py = rng.uniform(-420, 420, n), rng.uniform(-420, 420, n)
        wx, wy = frame.to_world(px, py)
        keep = obs.points_free(wx, wy)  # starts in free water only
        px, py, wx, wy = px[keep], py[keep], wx[keep], wy[keep]
        reach = rng.uniform(0, 80, px.size)
        length = reach[:, None] * rng.uniform(0, 1, (px.size, m))
        heading = rng.uniform(0, 2 * np.pi, (px.size, m))
        qx = px[:, None] + length * np.sin(heading)
        qy = py[:, None] + length * np.cos(heading)
        theirs = obs.segments_free(wx[:, None], wy[:, None], *frame.to_world(qx, qy))
        assert 0.5 < theirs.mean() < 1.0
        for kw in (
            {},
            {"starts_free": True},
            {"reach": reach},
            {"starts_free": True, "reach": reach},
        ):
            assert np.array_equal(obs.moves_free(px, py, qx, qy, frame.to_world, **kw), theirs)
    # a front far from every edge: clear, and nothing of it blocked; one near: not clear
    frame = _Frame(10.0, 0.0, 0.0)
    px, py = np.array([200.0, 210.0]), np.array([-150.0, -140.0])
    far = np.array([5.0, 5.0])
    assert obs.fan_clear(px, py, far, frame.to_world)
    qx = px[:, None] + np.array([[-5.0, 0.0, 5.0]])
    assert obs.moves_free(px, py, qx, py[:, None] + 0 * qx, frame.to_world).all()
    assert not obs.fan_clear(px, py, np.array([5.0, 400.0]), frame.to_world)
    assert obs.fan_clear(px[:0], py[:0], far[:0], frame.to_world)


def test_clearance_grows_obstacles_and_shrinks_the_boundary() -> None:
    obs = Obstacles.build(
        RaceArea(
            rect("bound", 0, 100, 0, 100, clearance=10.0),
            (rect("b", 40, 60, 40, 60, clearance=5.0),),
        )
    )
    assert obs is not None
    assert obs.points_free([5, 15, 36, 34], [50, 50, 50, 50]).tolist() == [False, True, False, True]
    assert obs.nearest_name([5.0], [50.0]) == BOUNDARY_NAME
    assert obs.nearest_name([37.0], [50.0]) == "b"


def test_land_cells_of_a_wind_grid_become_one_obstacle() -> None:
    y, x = np.mgrid[0:500:100.0, 0:500:100.0]
    nan = np.zeros(x.shape, dtype=bool)
    nan[2, 3] = True  # the node (300, 200)
    name, geom = land_obstacle(x, y, nan)
    assert name == "land"
    # one spacing round the node: every point whose interpolation uses it
    assert shapely.contains_xy(geom, [250.0, 390.0], [150.0, 290.0]).tolist() == [True, True]
    assert not shapely.contains_xy(geom, 150.0, 200.0)
    assert land_obstacle(x, y, np.zeros_like(nan)) is None
    assert obstacles_for(RaceArea()) is None


# ---------------------------------------------------------------------- isochrone
@pytest.fixture(scope="module")
def blocked_reach() -> tuple[LegResult, Obstacles]:
    obs = Obstacles.build(RaceArea(obstacles=(BLOCK,)))
    assert obs is not None
    res = route_isochrone(*REACH, T0, REACH_WIND, constant_polar(), reach_settings(), obstacles=obs)
    return res, obs


def test_blocked_reach_goes_round_the_near_corners(
    blocked_reach: tuple[LegResult, Obstacles],
) -> None:
    res, obs = blocked_reach
    assert track_free(res, obs)
    # constant speed: time = shortest length / speed, within 0.5 %
    assert res.time_s == pytest.approx(REACH_LENGTH / SPEED, rel=5e-3)
    assert res.distance_m == pytest.approx(REACH_LENGTH, rel=5e-3)
    assert res.distance_m > 2000.0 * 1.04  # not through the block
    assert np.min(res.track.x) == pytest.approx(-300.0, abs=15.0)  # the west corners
    assert np.max(res.track.x[1:]) < 0.0


def test_open_reach_is_straight() -> None:
    res = route_isochrone(*REACH, T0, REACH_WIND, constant_polar(), reach_settings())
    assert res.time_s == pytest.approx(2000.0 / SPEED, rel=2e-3)


def test_griddp_agrees_with_isochrone_round_the_block(
    blocked_reach: tuple[LegResult, Obstacles],
) -> None:
    iso, obs = blocked_reach
    dp = route_griddp(
        *REACH, T0, REACH_WIND, constant_polar(), reach_settings("griddp"), obstacles=obs
    )
    assert track_free(dp, obs)
    # the grid's corner nodes lie off the corners: within 1 % of the isochrone and of
    # the closed form
    assert dp.time_s == pytest.approx(iso.time_s, rel=1e-2)
    assert dp.time_s == pytest.approx(REACH_LENGTH / SPEED, rel=1e-2)
    assert np.max(dp.track.x[1:]) < 0.0


def test_beat_up_a_channel_tacks_at_its_edges() -> None:
    polar = laser_like_polar()
    tws = 6.0
    up, _ = polar.vmg_angles_deg(tws)
    width = 100.0
    # boards from the centre: the first crosses half the channel, then whole widths;
    # n tacks cover (width / 2 + n width) / tan(up) along it: 3.5 boards' worth -> 4 tacks
    along = (0.5 * width + 3.5 * width) / math.tan(math.radians(up))
    n_expected = 4
    channel = rect("channel", -width / 2, width / 2, -50.0, along + 50.0)
    obs = Obstacles.build(RaceArea(boundary=channel))
    assert obs is not None
    start = Start((0.0, 0.0), name="start")
    target = Target("line", (-width / 2 + 1, along), (width / 2 - 1, along), name="top")
    s = routing_settings(dt_s=5.0, tack_penalty_s=10.0, heading_step_deg=1.0)
    res = route_isochrone(start, target, T0, UniformWind(tws, 0.0), polar, s, obstacles=obs)
    assert track_free(res, obs)
    assert res.n_tacks == n_expected
    # the tacks are at the channel's edges, alternately (the last board has half a
    # board's width to spare, so the last tack may come early)
    tacks_x = np.array([m.x for m in res.manoeuvres if m.kind == "tack"])
    assert np.all(np.abs(tacks_x[:-1]) > 0.5 * width - 8.0)
    assert np.all(np.sign(tacks_x[1:]) == -np.sign(tacks_x[:-1]))
    # time: the along distance at the VMG, plus the penalties (within 3 %)
    vmg = float(polar.speed(tws, up)) * math.cos(math.radians(up))
    assert res.time_s == pytest.approx(along / vmg + n_expected * 10.0, rel=3e-2)


def test_a_start_inside_an_obstacle_is_a_clear_error() -> None:
    obs = Obstacles.build(RaceArea(obstacles=(rect("pier", -20, 20, -20, 20),)))
    with pytest.raises(RoutingError, match="no route round obstacle 'pier'"):
        route_isochrone(*REACH, T0, REACH_WIND, constant_polar(), reach_settings(), obstacles=obs)


def test_a_walled_off_target_is_refused_before_routing() -> None:
    wall = rect("reef", -1000, 1000, 900, 1000)
    obs = Obstacles.build(RaceArea(rect("bound", -800, 800, -200, 2200), (wall,)))
    for router in ("isochrone", "griddp"):
        with pytest.raises(RoutingError, match="no route round obstacle 'reef'"):
            route_leg(
                *REACH, T0, REACH_WIND, constant_polar(), reach_settings(router), obstacles=obs
            )


# ---------------------------------------------------------------------- registry
def test_registry_says_what_each_router_supports() -> None:
    assert {k: (e.current, e.obstacles) for k, e in ROUTERS.items()} == {
        "isochrone": (True, True),
        "griddp": (False, True),
        "spline": (False, False),
    }
    with pytest.raises(
        InputError,
        match="'spline': a race-area boundary or obstacles are "
        "honoured by the isochrone and griddp routers only",
    ):
        check_router_supports("spline", obstacles=True)
    with pytest.raises(InputError, match="supported by the isochrone router only"):
        check_router_supports("griddp", current=True)
    obs = Obstacles.build(RaceArea(obstacles=(BLOCK,)))
    with pytest.raises(InputError, match=r"set routing\.router: isochrone"):
        route_leg(*REACH, T0, REACH_WIND, constant_polar(), reach_settings("spline"), obstacles=obs)


def test_a_point_move_crosses_nothing_in_an_edges_box() -> None:
    # a zero-length move (a penalty pause) inside the bounding box of a long diagonal
    # edge but far from it: free (its two ends are collinear with every edge)
    tri = AreaPolygon("bound", (0.0, 1000.0, 0.0), (0.0, 1000.0, 1000.0))
    obs = Obstacles.build(RaceArea(tri))
    assert obs is not None
    assert obs.segments_free(
        [100.0, 500.0], [700.0, 500.0], [100.0, 500.0], [700.0, 500.0]
    ).tolist() == [True, False]


def test_generic_array_module_path_goes_round_the_same_way() -> None:
    # the path a CuPy backend takes (one chunk per step; the obstacle test on the host)
    # through a thin stand-in for NumPy: the same route round a smaller block
    import types

    fake = types.ModuleType("numpy_standin")
    fake.__getattr__ = lambda name: getattr(np, name)  # type: ignore[method-assign]
    obs = Obstacles.build(RaceArea(obstacles=(rect("block", -150, 250, 300, 500),)))
    start, target = Start((0.0, 0.0)), Target("line", (-20.0, 800.0), (20.0, 800.0))
    s = routing_settings(reach_settings(), dt_s=10.0)
    a = route_isochrone(start, target, T0, REACH_WIND, constant_polar(), s, obstacles=obs)
    b = route_isochrone(start, target, T0, REACH_WIND, constant_polar(), s, obstacles=obs, xp=fake)
    assert b.time_s == pytest.approx(a.time_s, rel=1e-12)
    assert np.min(a.track.x) < -140.0
