"""Masks, detections and observation policies from Python, on synthetic and real masks."""

import json

import numpy as np
import pytest

import ellreloc as E


def runs(mask):
    """COCO run lengths computed independently: column-major, starting with zeros."""
    flat = np.asarray(mask, dtype=bool).T.ravel()
    edges = np.flatnonzero(np.diff(flat.astype(np.int8))) + 1
    bounds = np.concatenate([[0], edges, [flat.size]])
    lengths = np.diff(bounds).tolist()
    return lengths if not flat[0] else [0] + lengths


def rectangle(h=120, w=160, box=(40, 30, 110, 80)):
    m = np.zeros((h, w), dtype=bool)
    x1, y1, x2, y2 = box
    m[y1:y2, x1:x2] = True
    return m


def disc(h=120, w=160, centre=(70.0, 60.0), r=30.0):
    y, x = np.mgrid[0:h, 0:w]
    return (x - centre[0]) ** 2 + (y - centre[1]) ** 2 <= r * r


@pytest.mark.parametrize("order", ["C", "F"])
@pytest.mark.parametrize("dtype", [bool, np.uint8])
def test_masks_from_numpy_are_coco_runs_in_any_memory_order(order, dtype):
    m = np.asarray(disc() ^ rectangle(), dtype=dtype, order=order)
    rle = E.RleMask.from_array(m)
    assert (rle.height, rle.width) == m.shape
    assert rle.counts == runs(m)
    assert rle.area == int(np.count_nonzero(m))
    assert np.array_equal(rle.to_array(), m.astype(bool))
    assert E.RleMask.from_array(m[::2, ::3]).counts == runs(m[::2, ::3])  # strided views, no copy
    coco = rle.to_coco()
    assert isinstance(coco["counts"], str) and E.RleMask.from_coco(coco).counts == rle.counts
    assert E.RleMask.from_coco({"size": coco["size"], "counts": coco["counts"].encode()}).counts == rle.counts
    assert E.RleMask.from_coco({"size": [m.shape[0], m.shape[1]], "counts": rle.counts}).counts == rle.counts


def test_mask_errors_name_what_is_wrong():
    with pytest.raises(ValueError, match=r"mask: expected a 2-D bool or uint8 numpy array, got a float64 array of shape \(4, 4\)"):
        E.RleMask.from_array(np.zeros((4, 4)))
    with pytest.raises(ValueError, match="got a list"):
        E.observation_from_mask([[0, 1], [1, 0]])
    with pytest.raises(ValueError, match="malformed compressed RLE string"):
        E.RleMask.from_coco({"size": [4, 4], "counts": "\x01"})
    with pytest.raises(ValueError, match="'size' must be two integers"):
        E.RleMask.from_coco({"size": "4x4", "counts": [16]})
    with pytest.raises(ValueError, match="needs 'size'"):
        E.Detection(0, [0, 0, 1, 1], mask={"counts": []})
    with pytest.raises(ValueError, match="runs do not add up"):
        E.RleMask(4, 4, [3, 2])


def test_regular_and_irregular_masks():
    rect = rectangle()
    verdict = E.test_regular_mask(rect)
    assert verdict.regular and bool(verdict) and verdict.quad_vertices == 4
    assert verdict.quadrilateral and verdict.outline_vertices == 4
    # A tilted rectangle: regular, but with no outline tolerance each pixel step is a vertex, and
    # the outline test alone turns it down.
    yy, xx = np.mgrid[0:120, 0:160]
    u, v = (xx - 80) * np.cos(0.3) + (yy - 60) * np.sin(0.3), (yy - 60) * np.cos(0.3) - (xx - 80) * np.sin(0.3)
    tilted = (abs(u) < 45) & (abs(v) < 25)
    strict = E.RegularMaskOptions()
    strict.outline_tolerance = 0.0
    assert E.test_regular_mask(tilted).regular
    turned_down = E.test_regular_mask(tilted, strict)
    assert turned_down.quadrilateral and not turned_down.regular and turned_down.outline_vertices > 4
    np.testing.assert_allclose(np.sort(verdict.corners[:, 0]), [39.5, 39.5, 109.5, 109.5], atol=1e-9)  # pixel edges
    assert not E.test_regular_mask(disc()).regular
    # A regular rectangle's observation under the paper's policy is the ellipse inscribed in it.
    r = E.observation_from_mask(rect, category=62, policy="paper")
    assert r.status == E.ObserveStatus.ok and r.observation.source == E.EllipseSource.mask
    assert r.observation.regular is True and r.observation.category == 62
    assert r.observation.box.to_array().tolist() == [39.5, 29.5, 109.5, 79.5]  # the outer pixel edges
    np.testing.assert_allclose(r.observation.ellipse.center, [74.5, 54.5], atol=1e-6)  # pixel centres
    np.testing.assert_allclose(r.observation.ellipse.axes, [35.0, 25.0], atol=1e-6)
    # A disc is not regular: the paper's policy falls back to the box; the moments fit the disc.
    d = E.observation_from_mask(disc(), policy="paper")
    assert d.observation.source == E.EllipseSource.box and d.observation.regular is False
    # The default policy fits the hull of a solid non-regular mask, and keeps the box below the threshold.
    solid = E.observe(E.Detection(0, d.observation.box, mask=disc()), 160, 120).observation
    assert solid.source == E.EllipseSource.mask and solid.regular is False
    strict = E.ObserveOptions()
    strict.solid_min_solidity = 1.0
    assert E.observation_from_mask(disc(), policy="solid", options=strict).observation.source == E.EllipseSource.box
    fit = E.fit_mask_ellipse(disc(r=30.0), E.MaskFitMethod.moments)
    np.testing.assert_allclose(fit.center, [70.0, 60.0], atol=1e-6)
    np.testing.assert_allclose(fit.axes, [30.0, 30.0], rtol=0.02)
    assert E.fit_mask_ellipse(np.zeros((8, 8), bool)) is None
    # The hull fit: a rectangle's hull is the rectangle, whose ellipse touches its sides.
    np.testing.assert_allclose(np.sort(np.unique(verdict.hull[:, 0])), [39.5, 109.5], atol=1e-9)
    hull_fit = E.fit_mask_ellipse(rect, E.MaskFitMethod.hull)
    np.testing.assert_allclose(hull_fit.axes, [35.0, 25.0], atol=1e-6)
    np.testing.assert_allclose(E.fit_mask_ellipse(disc(r=30.0), E.MaskFitMethod.hull).axes, [30.0, 30.0], rtol=0.03)


def test_box_observations_and_policies():
    d = E.Detection(56, E.Box(10, 20, 110, 70), score=0.8)
    r = E.observe(d, 640, 480, policy="bbox")
    assert r.observation.ellipse.axes.tolist() == [50.0, 25.0] and r.observation.score == 0.8
    assert E.observation_from_box(56, E.Box(10, 20, 110, 70), 640, 480).ellipse.center.tolist() == [60.0, 45.0]
    assert E.observation_from_box(56, E.Box(10, 20, 10, 70), 640, 480) is None
    assert E.observe(d, 640, 480, policy="given").status == E.ObserveStatus.no_ellipse
    assert E.observe(E.Detection(0, [5, 5, 5, 9]), 640, 480).status == E.ObserveStatus.invalid_box
    with pytest.raises(ValueError, match="policy: expected 'solid', 'paper', 'bbox', 'mask' or 'given'"):
        E.observe(d, 640, 480, policy="boxes")
    options = E.ObserveOptions()
    options.border_px = -1
    with pytest.raises(ValueError, match="options: border_px"):
        E.observe(d, 640, 480, options=options)


def test_a_lens_moves_observations_to_the_pinhole_image(data_dir):
    lens = E.read_lens(data_dir / "tum_fr2_desk" / "camera.yaml")
    raw_box = E.Box(20, 30, 140, 120)
    pinhole = lens.undistort_box(raw_box)
    assert pinhole.x1 > raw_box.x1 + 3 and pinhole.y1 > raw_box.y1 + 3  # fr2's lens pulls the corner inwards
    corner = lens.undistort_pixel([0.0, 0.0])
    assert np.allclose(lens.distort_pixel(corner), [0.0, 0.0], atol=1e-6)
    options = E.ObserveOptions()
    options.lens = lens
    r = E.observe(E.Detection(62, raw_box), 640, 480, policy="bbox", options=options)
    assert r.observation.box.x1 == pytest.approx(pinhole.x1) and r.observation.box.y2 == pytest.approx(pinhole.y2)
    assert np.allclose(r.observation.ellipse.center, [(pinhole.x1 + pinhole.x2) / 2, (pinhole.y1 + pinhole.y2) / 2])
    assert E.observe(E.Detection(62, raw_box), 320, 240, options=options).status == E.ObserveStatus.invalid_options
    with pytest.raises(ValueError, match="distortion: the radial distortion folds over"):
        E.Lens(lens.intrinsics, E.Distortion(k1=-0.9))
    # An ellipse is moved as its outline is; a lens without distortion moves nothing.
    raw = E.Ellipse([80, 70], [60, 25], 0.3)
    moved = lens.undistort_ellipse(raw)
    assert np.linalg.norm(moved.center - raw.center) > 3
    flat = E.Lens(lens.intrinsics, E.read_distortion(data_dir / "tum_fr3_cabinet" / "camera.yaml"))
    assert flat.distortion.is_zero()
    assert np.allclose(flat.undistort_ellipse(raw).center, raw.center) and flat.undistort_box(raw_box).x1 == 20


def test_real_masks_observe_as_from_the_file(data_dir):
    d = data_dir / "labelme_masks"
    frames = E.read_detections(d / "detections.json")
    raw = json.loads((d / "detections.rle_list.json").read_text())
    n = 0
    for frame, raw_frame in zip(frames, raw):
        for det, raw_det in zip(frame.detections, raw_frame["detections"]):
            array = det.mask.to_array()
            assert E.RleMask.from_array(array).counts == raw_det["mask"]["counts"] == runs(array)
            from_file = E.observe(det, array.shape[1], array.shape[0], policy="mask").observation
            from_array = E.observation_from_mask(array, category=det.category_id, box=det.bbox).observation
            assert from_array.ellipse.center.tolist() == from_file.ellipse.center.tolist()
            assert from_array.ellipse.axes.tolist() == from_file.ellipse.axes.tolist()
            n += 1
    assert n == 12


def test_frames_observe_like_the_relocalizer(fr2):
    camera, map_, frames = fr2
    frame = frames[0]
    observations = E.observe_frame(frame, camera, policy="bbox")
    assert len(observations) == len(frame.detections)
    for o, d in zip(observations, frame.detections):
        assert o.source == E.EllipseSource.box and o.category == d.category_id
        assert o.ellipse.center.tolist() == d.bbox.center.tolist()
    relocalizer = E.ObjectRelocalizer(map_, camera)
    assert [o.ellipse.center.tolist() for o in relocalizer.observe(frame)] == \
        [o.ellipse.center.tolist() for o in E.observe_frame(frame, camera)]
    with pytest.raises(ValueError, match="frame: expected a list of Detection"):
        E.observe_frame(3, camera)
