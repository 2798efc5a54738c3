"""Tests of the synthetic kitchen RGB-D renderer (annotators.simulation.kitchen_scene)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from numpy.typing import NDArray

from annotators.simulation.kitchen_scene import (
    DEFAULT_INTRINSICS,
    MAX_DEPTH,
    RenderedScene,
    SceneObject,
    camera_looking_at,
    camera_views,
    kitchen_objects,
    kitchen_regions,
    look_at,
    orbit_views,
    render_kitchen,
)

TABLE_OBJECTS = ("cereal_box", "red_cup", "bowl")


@pytest.fixture(scope="module")
def table() -> RenderedScene:
    """Default (table) view with noise."""
    return render_kitchen("table")


@pytest.fixture(scope="module")
def fridge() -> RenderedScene:
    """Fridge view with noise."""
    return render_kitchen("fridge")


def backproject(scene: RenderedScene, mask: NDArray[np.bool_]) -> NDArray[np.float64]:
    """World points (N x 3) of the masked pixels, computed from depth only."""
    k = scene.intrinsics
    v, u = np.nonzero(mask)
    z = scene.depth[v, u].astype(np.float64)
    pts = np.stack([(u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z, np.ones_like(z)], axis=1)
    return (pts @ scene.cam_to_world.T)[:, :3]


def surface_distance(obj: SceneObject, points_world: NDArray[np.float64]) -> NDArray[np.float64]:
    """Unsigned distance of world points to the object's modelled surface."""
    inv = np.linalg.inv(obj.pose)
    p = points_world @ inv[:3, :3].T + inv[:3, 3]
    w, d, h = obj.size
    if obj.shape == "box":
        q = np.abs(p) - np.array([w, d, h]) / 2
        outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
        inside = np.minimum(q.max(axis=1), 0.0)
        return np.abs(outside + inside)
    if obj.shape == "cylinder":  # open cup: wall + bottom disc
        r = np.hypot(p[:, 0], p[:, 1])
        wall = np.hypot(r - w / 2, np.maximum(np.abs(p[:, 2]) - h / 2, 0.0))
        bottom = np.hypot(p[:, 2] + h / 2, np.maximum(r - w / 2, 0.0))
        return np.minimum(wall, bottom)
    assert obj.shape == "sphere"  # half-ellipsoid shell, rim at z = +h/2
    rho = np.sqrt((p[:, 0] / (w / 2)) ** 2 + (p[:, 1] / (w / 2)) ** 2 + ((p[:, 2] - h / 2) / h) ** 2)
    assert np.all(p[:, 2] <= h / 2 + 0.005)
    return np.abs(rho - 1.0) * h  # conservative: h is the smallest semi-axis


def mean_hsv(scene: RenderedScene, name: str) -> tuple[float, float, float]:
    """Circular mean hue (OpenCV 0..180), mean S and V (0..255) of an object's pixels."""
    hsv = cv2.cvtColor(scene.color, cv2.COLOR_RGB2HSV)[scene.object_ids == scene.object(name).object_id]
    ang = hsv[:, 0].astype(np.float64) / 180.0 * 2 * np.pi
    hue = (np.degrees(np.arctan2(np.sin(ang).mean(), np.cos(ang).mean())) % 360.0) / 2.0
    return float(hue), float(hsv[:, 1].mean()), float(hsv[:, 2].mean())


def project(scene: RenderedScene, points_world: NDArray[np.float64]) -> NDArray[np.float64]:
    """Pixel coordinates (u, v) of world points."""
    k = scene.intrinsics
    pw = np.column_stack([points_world, np.ones(len(points_world))])
    pc = (pw @ scene.world_to_cam.T)[:, :3]
    assert np.all(pc[:, 2] > 0)
    return np.column_stack([k.fx * pc[:, 0] / pc[:, 2] + k.cx, k.fy * pc[:, 1] / pc[:, 2] + k.cy])


def box_corners(obj: SceneObject) -> NDArray[np.float64]:
    """World coordinates of the 8 corners of the object's bounding box."""
    half = np.array(obj.size) / 2
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64)
    local = signs * half
    return local @ obj.pose[:3, :3].T + obj.pose[:3, 3]


# --------------------------------------------------------------------------
def test_image_format_and_intrinsics(table: RenderedScene) -> None:
    k = table.intrinsics
    assert k == DEFAULT_INTRINSICS
    assert (k.fx, k.fy, k.cx, k.cy, k.width, k.height) == (570.0, 570.0, 319.5, 239.5, 640, 480)
    assert table.color.shape == (k.height, k.width, 3) and table.color.dtype == np.uint8
    assert table.depth.shape == (k.height, k.width) and table.depth.dtype == np.float32
    assert table.object_ids.shape == (k.height, k.width) and table.object_ids.dtype == np.int32
    for arr in (table.color, table.depth, table.object_ids):
        assert arr.flags["C_CONTIGUOUS"]
    assert np.isclose(k.cx, (k.width - 1) / 2) and np.isclose(k.cy, (k.height - 1) / 2)
    assert np.allclose(k.matrix(), [[570, 0, 319.5], [0, 570, 239.5], [0, 0, 1]])
    t = table.cam_to_world
    assert t.shape == (4, 4) and t.dtype == np.float64
    assert np.allclose(t[:3, :3] @ t[:3, :3].T, np.eye(3)) and np.isclose(np.linalg.det(t[:3, :3]), 1.0)
    assert np.allclose(t[3], [0, 0, 0, 1])
    assert table.view == "table"


def test_same_seed_is_byte_identical() -> None:
    a, b = render_kitchen("table", seed=7), render_kitchen("table", seed=7)
    assert a.color.tobytes() == b.color.tobytes()
    assert a.depth.tobytes() == b.depth.tobytes()
    assert a.object_ids.tobytes() == b.object_ids.tobytes()


def test_different_seed_changes_only_the_noise() -> None:
    a, b = render_kitchen("table", seed=1), render_kitchen("table", seed=2)
    assert np.array_equal(a.object_ids, b.object_ids)
    assert np.array_equal(a.depth > 0, b.depth > 0)
    assert not np.array_equal(a.color, b.color)
    assert not np.array_equal(a.depth, b.depth)
    dc = a.color.astype(np.int16) - b.color.astype(np.int16)
    assert 1.0 < dc.std() < 6.0  # two independent noises of sigma ~2 levels
    valid = a.depth > 0
    dd = (a.depth - b.depth)[valid]
    assert 0.0005 < dd.std() < 0.003  # two independent noises of sigma 1 mm


def test_noise_off_ignores_seed_and_is_smooth() -> None:
    a = render_kitchen("table", seed=1, noise=False)
    b = render_kitchen("table", seed=2, noise=False)
    assert a.color.tobytes() == b.color.tobytes() and a.depth.tobytes() == b.depth.tobytes()
    noisy = render_kitchen("table", seed=1)
    diff = noisy.color.astype(np.int16) - a.color.astype(np.int16)
    assert 1.0 < diff.std() < 4.0


@pytest.mark.parametrize(
    ("view", "name"),
    [("table", "cereal_box"), ("table", "red_cup"), ("table", "bowl"), ("fridge", "milk")],
)
def test_depth_backprojects_onto_object_surface(view: str, name: str) -> None:
    exact = render_kitchen(view, noise=False)
    obj = exact.object(name)
    mask = exact.object_ids == obj.object_id
    assert mask.sum() > 500
    dist = surface_distance(obj, backproject(exact, mask))
    assert dist.max() < 0.005
    assert np.median(dist) < 0.001
    noisy = render_kitchen(view, seed=3)
    dist_noisy = surface_distance(obj, backproject(noisy, mask))
    assert np.percentile(dist_noisy, 99.5) < 0.005


def test_background_depth_is_not_on_objects(table: RenderedScene) -> None:
    mask = (table.object_ids == 0) & (table.depth > 0)
    pts = backproject(table, mask)
    for obj in table.objects:
        # no furniture pixel lies inside an object's bounding box
        inv = np.linalg.inv(obj.pose)
        p = pts @ inv[:3, :3].T + inv[:3, 3]
        inside = np.all(np.abs(p) < np.array(obj.size) / 2 - 0.01, axis=1)
        assert not inside.any(), obj.name


def test_depth_range_and_no_data() -> None:
    up = render_kitchen(look_at((0.0, -1.0, 1.5), (0.0, -0.6, 3.0)), noise=False)
    assert up.view == "custom"
    assert up.depth.min() >= 0.0 and up.depth.max() <= MAX_DEPTH
    nodata = up.depth == 0
    assert nodata.sum() > 1000  # looking up into the empty sky above the walls
    assert np.all(up.object_ids[nodata] == 0)
    over = render_kitchen("overview")
    assert over.depth.max() <= MAX_DEPTH + 0.01


def test_table_view_sees_table_objects_fully_and_not_milk(table: RenderedScene) -> None:
    k = table.intrinsics
    for name in TABLE_OBJECTS:
        assert table.pixel_count(name) >= 500, name
        uv = project(table, box_corners(table.object(name)))
        assert np.all(uv[:, 0] > 5) and np.all(uv[:, 0] < k.width - 5), name
        assert np.all(uv[:, 1] > 5) and np.all(uv[:, 1] < k.height - 5), name
    assert table.pixel_count("milk") == 0
    visible = {o.name for o in table.visible_objects()}
    assert visible == set(TABLE_OBJECTS)
    # the table top (brown furniture) covers a good part of the image
    hsv = cv2.cvtColor(table.color, cv2.COLOR_RGB2HSV)
    brown = (table.object_ids == 0) & (hsv[..., 0] < 20) & (hsv[..., 1] > 100)
    assert brown.mean() > 0.3
    # floor and wall visible too: depth spans well beyond the table
    assert table.depth.max() > 2.0


def test_fridge_view_sees_milk_readable_size(fridge: RenderedScene) -> None:
    assert {o.name for o in fridge.visible_objects()} == {"milk"}
    milk = fridge.object("milk")
    v, u = np.nonzero(fridge.object_ids == milk.object_id)
    assert u.max() - u.min() >= 80  # wide enough for OCR
    k = fridge.intrinsics
    assert abs(u.mean() - k.cx) < 60 and abs(v.mean() - k.cy) < 60  # roughly centred
    assert u.min() > 5 and u.max() < k.width - 5 and v.min() > 5 and v.max() < k.height - 5
    assert 0.45 <= fridge.object_centroid_camera("milk")[2] <= 0.7
    # supporting shelf plane visible just below the carton
    below = fridge.depth[v.max() + 5 : v.max() + 40, u.min() : u.max()]
    assert np.all(below > 0)
    pts = backproject(
        fridge,
        np.pad(np.ones_like(below, dtype=bool), ((v.max() + 5, k.height - v.max() - 40), (u.min(), k.width - u.max()))),
    )
    shelf_z = milk.pose[2, 3] - milk.size[2] / 2
    assert np.allclose(pts[:, 2], shelf_z, atol=0.005)


def test_milk_text_is_printed_on_the_front(fridge: RenderedScene) -> None:
    milk = fridge.object("milk")
    assert milk.text == "MILK lactose free"
    mask = fridge.object_ids == milk.object_id
    hsv = cv2.cvtColor(fridge.color, cv2.COLOR_RGB2HSV)
    blue_text = mask & (np.abs(hsv[..., 0].astype(int) - 115) < 15) & (hsv[..., 1] > 120)
    dark_text = mask & (hsv[..., 2] < 90)
    assert blue_text.sum() > 300  # "MILK"
    assert dark_text.sum() > 150  # "lactose free"
    vb, _ = np.nonzero(blue_text)
    vd, _ = np.nonzero(dark_text)
    assert vb.mean() < vd.mean()  # MILK above the second line


def test_colours_match_object_ids(table: RenderedScene, fridge: RenderedScene) -> None:
    h, s, v = mean_hsv(table, "red_cup")
    assert min(h, 180 - h) < 8 and s > 150
    h, s, v = mean_hsv(table, "cereal_box")
    assert 20 <= h <= 35 and s > 150 and v > 150
    h, s, v = mean_hsv(table, "bowl")
    assert 100 <= h <= 130 and s > 150
    h, s, v = mean_hsv(fridge, "milk")
    assert s < 40 and v > 170
    colours = {o.name: o.color for o in table.objects}
    assert colours == {"cereal_box": "yellow", "red_cup": "red", "bowl": "blue", "milk": "white"}


def test_ground_truth_metadata() -> None:
    objs = {o.name: o for o in kitchen_objects()}
    assert set(objs) == {"cereal_box", "red_cup", "bowl", "milk"}
    assert len({o.object_id for o in objs.values()}) == 4 and all(o.object_id > 0 for o in objs.values())
    assert {n: o.object_class for n, o in objs.items()} == {
        "cereal_box": "CerealBox",
        "red_cup": "Cup",
        "bowl": "Bowl",
        "milk": "Milk",
    }
    assert {n: o.shape for n, o in objs.items()} == {
        "cereal_box": "box",
        "red_cup": "cylinder",
        "bowl": "sphere",
        "milk": "box",
    }
    assert {n: o.size_class for n, o in objs.items()} == {
        "cereal_box": "large",
        "red_cup": "small",
        "bowl": "medium",
        "milk": "medium",
    }
    assert {n: o.region for n, o in objs.items()} == {
        "cereal_box": "table",
        "red_cup": "table",
        "bowl": "table",
        "milk": "fridge",
    }
    assert objs["milk"].text == "MILK lactose free"
    assert all(o.text == "" for n, o in objs.items() if n != "milk")
    # table objects rest on the table top (0.75 m), >= 8 cm apart
    table_objs = [objs[n] for n in TABLE_OBJECTS]
    for o in table_objs:
        assert np.isclose(o.pose[2, 3] - o.size[2] / 2, 0.75)
    for i, a in enumerate(table_objs):
        for b in table_objs[i + 1 :]:
            gap = np.abs(a.pose[:2, 3] - b.pose[:2, 3]) - (np.array(a.size[:2]) + b.size[:2]) / 2
            assert gap.max() >= 0.08, (a.name, b.name)


def test_object_centroid_projects_into_its_pixels(table: RenderedScene) -> None:
    k = table.intrinsics
    for name in TABLE_OBJECTS:
        c = table.object_centroid_camera(name)
        u, v = k.fx * c[0] / c[2] + k.cx, k.fy * c[1] / c[2] + k.cy
        vs, us = np.nonzero(table.object_ids == table.object(name).object_id)
        assert us.min() <= u <= us.max() and vs.min() <= v <= vs.max(), name


def test_moved_object_appears_moved(table: RenderedScene) -> None:
    offset = np.array([0.12, 0.10, 0.0])
    moved = render_kitchen("table", moved={"red_cup": offset})
    before, after = table.object("red_cup"), moved.object("red_cup")
    assert np.allclose(after.pose[:3, 3], before.pose[:3, 3] + offset)
    assert after.region == "table"
    oid = before.object_id
    c0 = np.array(np.nonzero(table.object_ids == oid)).mean(axis=1)
    c1 = np.array(np.nonzero(moved.object_ids == oid)).mean(axis=1)
    assert np.linalg.norm(c1 - c0) > 30  # pixels
    expected = project(moved, after.pose[None, :3, 3])[0][::-1]
    assert np.linalg.norm(c1 - expected) < 15
    # the other objects did not move
    for name in ("cereal_box", "bowl"):
        assert np.allclose(moved.object(name).pose, table.object(name).pose)
        m = table.object_ids == table.object(name).object_id
        assert np.array_equal(m, moved.object_ids == table.object(name).object_id)


def test_moved_with_full_pose_changes_region() -> None:
    pose = np.eye(4)
    pose[:3, 3] = (0.0, 0.15, 0.75 + 0.10)
    scene = render_kitchen("table", moved={"milk": pose})
    milk = scene.object("milk")
    assert np.allclose(milk.pose, pose) and milk.region == "table"
    assert scene.pixel_count("milk") > 500
    with pytest.raises(ValueError, match="unknown object"):
        render_kitchen("table", moved={"banana": np.zeros(3)})
    with pytest.raises(ValueError, match="4x4"):
        render_kitchen("table", moved={"milk": np.zeros(2)})


def test_regions_contain_their_objects() -> None:
    regions = {r.name: r for r in kitchen_regions()}
    assert set(regions) == {"table", "fridge"}
    for r in regions.values():
        assert r.pose.shape == (4, 4) and len(r.size) == 3
        assert all(s > 0 for s in r.size)
    for obj in kitchen_objects():
        assert regions[obj.region].contains(obj.pose[:3, 3]), obj.name
        others = [r for n, r in regions.items() if n != obj.region]
        assert not any(r.contains(obj.pose[:3, 3]) for r in others)
    table = regions["table"]
    low = table.pose[2, 3] - table.size[2] / 2
    assert low <= 0.75 <= low + 0.1 and table.size[2] >= 0.4  # top surface and space above


def test_named_views_and_region_lookup() -> None:
    views = camera_views()
    assert set(views) >= {"table", "fridge", "overview"}
    assert camera_looking_at("table") == "table"
    assert camera_looking_at("FRIDGE") == "fridge"
    with pytest.raises(ValueError, match="table"):
        camera_looking_at("garage")
    with pytest.raises(ValueError, match="unknown view"):
        render_kitchen("garage")
    # table view: robot head ~1.4 m high, 1.0-1.3 m from the table, looking down 35-45 deg
    t = views["table"]
    assert 1.3 <= t[2, 3] <= 1.5
    assert 1.0 <= np.hypot(t[0, 3], t[1, 3]) <= 1.3
    pitch = np.degrees(np.arcsin(-t[2, 2]))
    assert 35.0 <= pitch <= 45.0
    over = render_kitchen("overview")
    assert {o.name for o in over.visible_objects(min_pixels=100)} == {"cereal_box", "red_cup", "bowl", "milk"}


def test_orbit_views_are_distinct_and_see_the_table_objects() -> None:
    poses = orbit_views(5)
    assert len(poses) == 5
    eyes = np.array([p[:3, 3] for p in poses])
    assert min(np.linalg.norm(a - b) for i, a in enumerate(eyes) for b in eyes[i + 1 :]) > 0.2
    for pose in poses:
        scene = render_kitchen(pose, noise=False)
        for name in TABLE_OBJECTS:
            assert scene.pixel_count(name) >= 500, name
