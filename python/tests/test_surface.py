"""The rest of the bound surface: small geometry helpers, every option field reaching the
library, result fields, the camera envelope and the simulator's options."""

import enum
import math

import numpy as np
import pytest

import ellreloc as E


def test_geometry_helpers():
    a, b = E.Box(0, 0, 4, 2), E.Box(1, 1, 6, 5)
    i = a.intersection(b)
    assert (i.x1, i.y1, i.x2, i.y2) == (1, 1, 4, 2) and a.is_valid() and not E.Box(3, 0, 1, 1).is_valid()
    assert a.to_array().tolist() == [0, 0, 4, 2] and a.center.tolist() == [2, 1]
    e = E.Ellipse([10.0, 20.0], [6.0, 2.0], 0.7)
    back = E.Ellipse.from_gaussian(e.center, e.covariance())
    np.testing.assert_allclose([*back.center, *back.axes, back.angle], [10, 20, 6, 2, 0.7])
    assert E.Ellipse.from_gaussian([0, 0], np.zeros((2, 2))) is None
    outline = e.sample_boundary(4096)
    box = e.bounding_box()
    np.testing.assert_allclose([box.x1, box.y1, box.x2, box.y2], [*outline.min(0), *outline.max(0)], atol=1e-3)
    assert e.is_valid() and e.contains([10, 20]) and not e.contains([20, 20])
    R = E.Pose.look_at([1, 2, 3], [0, 0, 0]).R_cw
    q = E.Ellipsoid([1, 2, 3], [0.3, 0.2, 0.1], R)
    np.testing.assert_allclose(q.shape_matrix(), R @ np.diag([0.09, 0.04, 0.01]) @ R.T, atol=1e-15)
    assert q.volume == pytest.approx(4 / 3 * math.pi * 0.006) and q.is_valid() and q.contains([1, 2, 3])
    again = E.Ellipsoid.from_dual_quadric(-2.5 * q.dual_quadric())
    np.testing.assert_allclose(again.shape_matrix(), q.shape_matrix(), atol=1e-12)
    np.testing.assert_allclose(again.center, q.center)
    pose = E.Pose(R, [0.1, 0.2, 0.3])
    assert pose.is_valid() and pose.t_cw.tolist() == [0.1, 0.2, 0.3]
    assert E.Intrinsics(500, 500, 320, 240, 640, 480).K.tolist() == [[500, 0, 320], [0, 500, 240], [0, 0, 1]]


def leaves(obj, prefix=""):
    """(path, value) of every field of an options object, nested groups walked."""
    for name in dir(obj):
        if name.startswith("_"):
            continue
        value = getattr(obj, name)
        if callable(value):
            continue
        if type(value).__module__.startswith("ellreloc") and not isinstance(value, enum.Enum) \
                and not hasattr(type(value), "__members__"):
            yield from leaves(value, f"{prefix}{name}.")
        elif hasattr(type(value), "__members__"):
            yield f"{prefix}{name}", type(value)(int(value))  # a copy: enum fields are returned by reference
        else:
            yield f"{prefix}{name}", value


def changed(value):
    """Another valid value of a field: a flipped bool, another enum member, a smaller number."""
    if isinstance(value, bool):
        return not value
    if isinstance(value, np.ndarray):
        return value * 0.5
    if hasattr(type(value), "__members__"):
        members = list(type(value).__members__.values())
        return members[(members.index(value) + 1) % len(members)]
    if isinstance(value, int):
        return value + 1
    return value * 0.5 if value > 0 else 0.25


def assign(obj, path, value):
    *groups, field = path.split(".")
    for g in groups:
        obj = getattr(obj, g)
    setattr(obj, field, value)


def same(a, b):
    return np.array_equal(a, b) if isinstance(a, np.ndarray) else a == b


def lookup(obj, path):
    for g in path.split("."):
        obj = getattr(obj, g)
    return obj


def test_every_relocalizer_and_mapper_option_reaches_the_library(fr2, office):
    camera, map_, _ = fr2
    options = E.RelocalizerOptions()
    fields = [(p, v) for p, v in leaves(options) if p != "envelope"]
    assert len(fields) > 40
    for path, value in fields:
        assign(options, path, changed(value))
    assert options.validate() == ""
    copied = E.ObjectRelocalizer(map_, camera, options).options  # a copy made by the C++ library
    for path, value in fields:
        assert same(lookup(copied, path), changed(value)), path
    mapper_options = E.MapperOptions()
    mapper_options.mode = E.MappingMode.boxes  # a unit_metres other than 1 is for boxes mode
    mapper_fields = [(p, v) for p, v in leaves(mapper_options) if p not in ("mode", "lens")]
    for path, value in mapper_fields:
        assign(mapper_options, path, changed(value))
    assert mapper_options.validate() == ""
    mapped = E.Mapper(office[1], mapper_options).options
    for path, value in mapper_fields:
        assert same(lookup(mapped, path), changed(value)), path
    preset = E.RelocalizerOptions.oa_slam()
    assert preset.search.sampler == E.HypothesisSampler.exhaustive and preset.scoring.overlap == E.OverlapMeasure.box_iou
    bad = E.RelocalizerOptions()
    bad.refinement.refiner.object_loss_scale = -1
    assert "refinement.refiner" in bad.validate()


def test_observe_options_reach_the_library():
    mask = np.zeros((100, 100), bool)
    mask[20:60, 10:90] = True
    options = E.ObserveOptions()
    assert options.validate() == ""
    default = E.observation_from_mask(mask, policy="paper", options=options).observation
    options.regular_fit = E.MaskFitMethod.moments  # same moments: semi-axis 2 sigma = side / sqrt(3)
    moments = E.observation_from_mask(mask, policy="paper", options=options).observation
    np.testing.assert_allclose(moments.ellipse.axes, [80 / math.sqrt(3), 40 / math.sqrt(3)], rtol=1e-3)
    assert not np.allclose(moments.ellipse.axes, default.ellipse.axes)
    options.regular = E.RegularMaskOptions()
    options.regular.min_pixels = 10_000  # too few pixels to tell: not regular, the box's ellipse
    assert E.observation_from_mask(mask, policy="paper", options=options).observation.source == E.EllipseSource.box
    verdict = E.test_regular_mask(mask)
    assert verdict.hull_vertices >= 4 and verdict.solidity == pytest.approx(1.0) and verdict.fill == pytest.approx(1.0)
    assert verdict.core_fill >= 0.95 and verdict.triangle_fill > 1.15 and not verdict.touches_border
    assert verdict.max_corner_angle_deg == pytest.approx(90) and verdict.min_corner_angle_deg == pytest.approx(90)
    wrong_size = E.Detection(1, [10, 20, 90, 60], mask=np.ones((5, 5), bool))
    r = E.observe(wrong_size, 100, 100, policy="mask")
    assert r.observation.source == E.EllipseSource.box and r.note and isinstance(r, E.ObserveResult)
    assert E.observation_from_box(1, E.Box(0, 10, 30, 40), 100, 100).truncated


def test_results_and_envelope(fr2, data_dir):
    camera, map_, frames = fr2
    truth = E.read_trajectory(data_dir / "tum_fr2_desk" / "keyframes.groundtruth.txt")
    envelope = E.CameraEnvelope.from_keyframes([p.pose for p in truth])
    assert all(envelope.admits(p.pose) for p in truth)
    raised = truth[0].pose.T_wc
    raised[:3, 3] += 3 * envelope.up
    high = E.Pose.from_T_wc(raised)
    assert not envelope.admits(high) and envelope.min_height < envelope.max_height
    assert 0 <= envelope.min_tilt_deg < envelope.max_tilt_deg <= 180
    upright = E.CameraEnvelope.upright([0, -2, 0])  # the fr2 map's frame: the first keyframe's camera
    assert upright.up.tolist() == [0, -1, 0] and upright.max_tilt_deg == 90 and upright.admits(high)
    assert all(upright.admits(p.pose) for p in truth)
    with pytest.raises(ValueError):
        E.CameraEnvelope.upright([0, 0, 0])
    with pytest.raises(ValueError):
        E.CameraEnvelope.upright([0, 0, 1], 0)
    with pytest.raises(ValueError, match="max_roll_deg"):
        E.CameraEnvelope.upright([0, 0, 1], 90, 0)
    # The vertical, independently of the map: the up most orthogonal to the keyframes' image rows.
    rights = np.array([p.pose.T_wc[:3, 0] for p in truth])
    vertical = np.linalg.eigh(rights.T @ rights)[1][:, 0]
    vertical *= np.sign(vertical @ envelope.up)
    level = E.CameraEnvelope.upright(vertical, 90, 45)  # keyframes roll at most 12 degrees
    assert level.max_roll_deg == 45 and all(level.admits(p.pose) for p in truth)
    relocalizer = E.ObjectRelocalizer(map_, camera, envelope=envelope)
    r = relocalizer.relocalize(frames[0])
    assert isinstance(r, E.RelocalizationResult) and r.success and r.hypotheses > 0 and r.iterations >= 0
    assert r.cost >= 0 and r.time_ms > 0 and not r.budget_exhausted and r.few_object_hypotheses >= 0
    assert all(isinstance(m, E.Match) and 0 < m.credit <= m.overlap + 1e-12 for m in r.matches)
    assert relocalizer.left_out == []
    budget = E.SearchBudget()
    budget.max_hypotheses = 0
    none = E.ObjectRelocalizer(map_, camera, search={"budget": budget}).relocalize(frames[0])
    assert none.status == E.RelocalizationStatus.no_consistent_hypothesis and none.reason
    # The fr2 map has no camera envelope: its objects tell its up, which the relocalizer keeps the
    # camera upright about.
    found = E.estimate_map_up(map_)
    assert found["objects"] == 45 and found["t"] >= 2.5 and found["up"] @ vertical > math.cos(math.radians(10))
    assert E.estimate_map_up(map_, min_t=10) is None
    upright_by_objects = E.ObjectRelocalizer(map_, camera, envelope=None)
    assert upright_by_objects.up_from_objects["up"].tolist() == found["up"].tolist()
    assert upright_by_objects.options.envelope.max_tilt_deg == 90
    assert upright_by_objects.options.envelope.max_roll_deg == 45
    np.testing.assert_allclose(upright_by_objects.options.envelope.up, found["up"])
    anywhere = E.ObjectRelocalizer(map_, camera, map_envelope=False)
    assert anywhere.options.envelope is None and anywhere.up_from_objects is None
    assert relocalizer.up_from_objects is None  # an envelope given is used as given
    skipped = relocalizer.relocalize([E.Observation(999, E.Ellipse([320, 240], [40, 20]))])
    assert skipped.skipped and skipped.skipped[0][0] == 0


def test_refinement_and_gravity_results(office):
    scene, camera, map_ = office
    truth = E.sim.query_trajectory(scene, 2, seed=4)[0]
    observations, objects = E.sim.observe_map(map_, camera, truth)
    matches = [E.EllipseMatch(o.ellipse, map_.objects[j].ellipsoid) for o, j in zip(observations, objects)]
    assert matches[0].observed.center.tolist() == observations[0].ellipse.center.tolist()
    assert matches[0].sigma == 1.0 and E.EllipseMatch(matches[0].observed, matches[0].ellipsoid, 0.5).sigma == 0.5
    with pytest.raises(ValueError, match="sigma"):
        E.EllipseMatch(matches[0].observed, matches[0].ellipsoid, sigma=0.0)
    shifted = truth.T_wc
    shifted[:3, 3] += 0.03
    start = E.Pose.from_T_wc(shifted)
    gravity = E.GravityPrior([0, -1, 0], [0, 0, 1], sigma_deg=1.0)
    assert gravity.up_in_camera.tolist() == [0, -1, 0] and gravity.up_in_map.tolist() == [0, 0, 1]
    assert gravity.sigma_deg == 1.0
    with pytest.raises(ValueError, match="GravityPrior"):
        E.GravityPrior([0, 0, 0])
    options = E.RefinerOptions()
    options.backend = E.RefinerBackend.ceres
    options.object_loss = E.RobustLoss.huber
    result = E.refine_pose(camera, start, matches, options=options, gravity=E.GravityPrior.at_pose(truth))
    assert isinstance(result, E.RefinementResult) and result.iterations > 0 and result.message == ""
    assert len(result.object_residuals) == len(matches) and max(result.object_residuals) < 0.01
    assert result.point_residuals == [] and result.converged
    assert E.pose_error(result.pose, truth).position_cm < 0.5


def test_mapping_reports_and_stats(office):
    scene, camera, _ = office
    mapper = E.Mapper(camera)
    reports = []
    for i, pose in enumerate(E.sim.mapping_trajectory(scene, 6)):
        frame = E.sim.render(scene, camera, pose)
        reports.append(mapper.add_keyframe(pose, E.sim.detect(scene, frame, "realistic", seed=i),
                                           E.sim.noisy_depth(frame, "realistic", seed=i)))
    assert all(isinstance(r, E.KeyframeReport) for r in reports) and reports[0].new_objects > 0
    assert sum(r.tracked_2d + r.matched_3d + r.new_objects for r in reports) == sum(r.used for r in reports)
    assert all(r.ignored >= 0 for r in reports)
    stats = mapper.stats
    assert isinstance(stats, E.MapperStats) and stats.keyframes == 6 and stats.objects + stats.candidates > 5
    assert stats.voxels > 0 and stats.memory_bytes > 0 and stats.up.tolist() == [0, 0, 1]
    objects = mapper.objects()
    assert [o.object.id for o in objects] == [o.id for o in mapper.map().objects] and len(objects) == stats.objects
    for o in objects:  # voxel mode: each ellipsoid is the one inscribed in its cuboid
        assert isinstance(o, E.MappedObject) and o.observations >= 3 and o.voxels > 0 and not o.depth_from_size
        assert isinstance(o.cuboid, E.Cuboid) and o.memory_bytes > 0
        np.testing.assert_allclose(o.cuboid.center, o.object.ellipsoid.center, atol=1e-9)
        np.testing.assert_allclose(sorted(o.cuboid.half), sorted(o.object.ellipsoid.axes), rtol=1e-9)
        corners = o.cuboid.corners()
        assert corners.shape == (8, 3)
        np.testing.assert_allclose(corners.mean(axis=0), o.cuboid.center, atol=1e-9)
    quality = E.map_quality(mapper.map(), camera, [(pose, [])])
    assert isinstance(quality, E.MapQuality) and quality.boxes == 0 and quality.explained == 0
    assert quality.mean_best_iou == 0


def test_simulator_options_and_summary(tmp_path):
    realistic, hard = E.sim.NoiseModel.preset("realistic"), E.sim.NoiseModel.preset(E.sim.NoiseLevel.hard)
    assert hard.miss_rate > realistic.miss_rate and E.sim.NoiseModel().miss_rate == 0
    scene = E.sim.make_scene("sparse", 2)
    camera = E.Intrinsics(525.0, 525.0, 319.5, 239.5, 640, 480)
    frame = E.sim.render(scene, camera, E.sim.mapping_trajectory(scene, 4)[0])
    assert isinstance(frame, E.sim.RenderedFrame) and isinstance(scene, E.sim.Scene) and scene.room_half_size > 1
    everything_missed = E.sim.NoiseModel()
    everything_missed.miss_rate = 1.0
    assert E.sim.detect(scene, frame, everything_missed, seed=0) == []
    summary = E.sim.write_simulation(tmp_path, "sparse", seed=1, noise="none", mapping_frames=3, query_frames=2,
                                     write_rgb=False)
    assert isinstance(summary, E.sim.SimulationSummary) and summary.query_frames == 2
    assert summary.query_detections > 0 and summary.objects == E.sim.make_scene("sparse", 1).object_count
    assert all((tmp_path / f).exists() for f in summary.files)
    a = E.read_associations(tmp_path / "mapping" / "associations.txt")
    assert len(a) == 3 and isinstance(a[0], E.Association) and a[0].depth_time == a[0].rgb_time


def test_option_groups_are_standalone_objects_with_the_library_defaults():
    options, mapper = E.RelocalizerOptions(), E.MapperOptions()
    groups = {"search": E.SearchOptions, "scoring": E.ScoringOptions, "few_objects": E.FewObjectOptions,
              "gravity": E.GravityOptions, "refinement": E.RefinementOptions, "acceptance": E.AcceptanceOptions}
    for name, cls in groups.items():
        fresh = cls()
        assert dict(leaves(fresh)) == dict(leaves(getattr(options, name))), name
        setattr(options, name, fresh)  # groups can be replaced whole
    assert dict(leaves(E.FewObjectSolverOptions())) == dict(leaves(options.few_objects.solver))
    assert dict(leaves(E.VoxelOptions())) == dict(leaves(mapper.voxels))
    assert dict(leaves(E.TrackingOptions())) == dict(leaves(mapper.tracking))
    scoring = E.ScoringOptions()
    scoring.min_inliers = 0
    options.scoring = scoring
    assert options.validate() == "scoring.min_inliers is below 1"


def test_pose_errors_keypoints_and_verdicts_are_plain_objects():
    e = E.PoseError()
    e.position_cm, e.rotation_deg = E.VALID_POSITION_CM - 0.1, E.VALID_ROTATION_DEG - 0.1
    assert e.valid
    e.position_cm = E.VALID_POSITION_CM  # the bounds themselves are not valid
    assert not e.valid
    summary = E.summarize([e])
    assert isinstance(summary, E.Summary) and summary.valid == 0 and summary.relocalized == 1
    k = E.Keypoint(3, [10.5, 20.0])
    frame = E.DetectionFrame("rgb/2.0.png", [], [k])
    assert frame.keypoints[0].point_index == 3 and frame.keypoints[0].uv.tolist() == [10.5, 20.0]
    assert E.DetectionFrame("x.png", keypoints=np.array([[3, 10.5, 20.0]])).keypoints[0].point_index == 3
    assert isinstance(E.test_regular_mask(np.ones((10, 10), bool)), E.RegularVerdict)
