"""ellreloc.sim from Python: scenes, rendering and noise, checked against the rendered pixels."""

import numpy as np

import ellreloc as E


def test_scenes_are_seeded():
    a, b = E.sim.make_scene("cluttered", 7), E.sim.make_scene(E.sim.ScenePreset.cluttered, 7)
    assert a.object_count == b.object_count >= 30
    assert np.array_equal(a.points, b.points) and a.points.shape[1] == 3
    assert [o.id for o in a.ground_truth_map().objects] == [o.id for o in b.ground_truth_map().objects]
    assert E.sim.make_scene("sparse", 1).object_count < 10


def test_rendering_masks_boxes_and_depth_agree(office):
    scene, camera, map_ = office
    pose = E.sim.mapping_trajectory(scene, 8)[3]
    frame = E.sim.render(scene, camera, pose)
    assert frame.depth.shape == frame.instance.shape == (480, 640)
    assert frame.depth.dtype == np.float32 and frame.instance.dtype == np.int16
    assert not frame.depth.flags.writeable and frame.depth.base is not None  # a view, not a copy
    seen = 0
    for i in range(scene.object_count):
        pixels = frame.instance == i
        assert frame.visible_pixels[i] == pixels.sum()
        assert np.array_equal(frame.masks[i].to_array(), pixels) if pixels.any() else frame.masks[i].area == 0
        if pixels.any():
            ys, xs = np.nonzero(pixels)
            box = frame.boxes[i]
            assert (box.x1, box.y1, box.x2, box.y2) == (xs.min() - 0.5, ys.min() - 0.5, xs.max() + 0.5, ys.max() + 0.5)
            assert (frame.depth[pixels] > 0).all()
            seen += 1
    assert seen >= 5
    detections = E.sim.detect(scene, frame, "none", seed=0)
    assert sorted(d.object_id for d in detections) == [i for i in range(scene.object_count)
                                                        if frame.visible_pixels[i] >= 150]
    noisy = E.sim.noisy_depth(frame, "realistic", seed=1)
    assert noisy.shape == (480, 640) and (noisy[frame.depth == 0] == 0).all()  # no reading stays none
    near = (frame.depth > 0) & (frame.depth < 5)
    assert 0 < np.abs(noisy - frame.depth)[near].max() < 0.5


def test_map_observations_and_perturbed_maps(office):
    scene, camera, map_ = office
    pose = E.sim.query_trajectory(scene, 3, seed=1)[0]
    observations, objects = E.sim.observe_map(map_, camera, pose)
    assert len(observations) == len(objects) > 3
    for o, j in zip(observations, objects):
        projected = E.project(map_.objects[j].ellipsoid, camera, pose)
        assert o.ellipse.center.tolist() == projected.center.tolist() and o.category == map_.objects[j].category
    noisy, _ = E.sim.observe_map(map_, camera, pose, centre_sigma_px=3.0, seed=2)
    assert noisy[0].ellipse.center.tolist() != observations[0].ellipse.center.tolist()
    moved = E.sim.perturb_map(map_, E.sim.NoiseModel.preset("hard"), seed=3)
    shifts = [np.linalg.norm(a.ellipsoid.center - b.ellipsoid.center) for a, b in zip(moved.objects, map_.objects)]
    assert len(moved) == len(map_) and 0 < np.median(shifts) < 0.3
