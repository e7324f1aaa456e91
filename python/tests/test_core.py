"""Geometry bindings against independent numpy computations."""

import math
import pickle

import numpy as np
import pytest

import ellreloc as E


def rotation(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def gaussian(e):
    c, s = math.cos(e.angle), math.sin(e.angle)
    R = np.array([[c, -s], [s, c]])
    return e.center, R @ np.diag(e.axes**2) @ R.T


def sqrtm(S):
    w, V = np.linalg.eigh(S)
    return V @ np.diag(np.sqrt(w)) @ V.T


def test_ellipse_matrices_and_pickle():
    e = E.Ellipse([320.0, 240.0], [80.0, 30.0], 0.4)
    m, S = gaussian(e)
    np.testing.assert_allclose(e.covariance(), S, rtol=1e-12)
    C = e.dual_conic()
    np.testing.assert_allclose(C[:2, :2], S - np.outer(m, m), rtol=1e-12)
    np.testing.assert_allclose(np.linalg.inv(e.conic()) / -np.linalg.inv(e.conic())[2, 2], C, rtol=1e-9, atol=1e-9)
    back = E.Ellipse.from_dual_conic(-3.0 * C)
    np.testing.assert_allclose(back.center, e.center)
    np.testing.assert_allclose(back.axes, e.axes)
    assert pickle.loads(pickle.dumps(e)).angle == e.angle
    pts = e.sample_boundary(16)
    assert pts.shape == (16, 2)
    r = [np.linalg.norm(np.linalg.solve(sqrtm(S), p - m)) for p in pts]
    np.testing.assert_allclose(r, 1.0, rtol=1e-12)
    assert E.Ellipse.from_dual_conic(np.zeros((3, 3))) is None
    assert E.Ellipse.inscribed_in_box(E.Box(0, 0, 10, 4)).axes.tolist() == [5.0, 2.0]


def test_projection_matches_numpy_and_the_silhouette():
    rng = np.random.default_rng(1)
    K = E.Intrinsics(500, 510, 320, 240, 640, 480)
    q = E.Ellipsoid([0.3, -0.2, 0.1], [0.4, 0.2, 0.1], rotation(rng))
    pose = E.Pose.look_at([2.5, 1.0, 1.2], [0.0, 0.0, 0.0])
    e = E.project(q, K, pose)
    P = K.K @ pose.T_cw[:3]
    C = P @ q.dual_quadric() @ P.T
    C = C / -C[2, 2]
    centre = -C[:2, 2]
    cov = C[:2, :2] + np.outer(centre, centre)
    np.testing.assert_allclose(e.center, centre, rtol=1e-10)
    np.testing.assert_allclose(np.sort(e.axes**2), np.sort(np.linalg.eigvalsh(cov)), rtol=1e-9)
    # Every surface point projects inside the ellipse, and the outline is reached.
    x = pose.transform(q.sample_surface(4000))
    uv = (K.K @ x.T).T
    uv = uv[:, :2] / uv[:, 2:]
    r = np.sqrt(np.einsum("ij,jk,ik->i", uv - centre, np.linalg.inv(cov), uv - centre))
    assert r.max() <= 1 + 1e-9 and r.max() > 0.99
    assert E.project(q, K, E.Pose.look_at([0.3, -0.2, 0.1], [1, 0, 0])) is None  # camera inside


def test_distances_match_their_formulas():
    a = E.Ellipse([100.0, 80.0], [40.0, 15.0], 0.3)
    b = E.Ellipse([110.0, 90.0], [30.0, 20.0], -0.5)
    (m1, S1), (m2, S2) = gaussian(a), gaussian(b)
    r1 = sqrtm(S1)
    w2 = np.sum((m1 - m2) ** 2) + np.trace(S1 + S2 - 2 * sqrtm(r1 @ S2 @ r1))
    assert E.wasserstein_squared(a, b) == pytest.approx(w2, rel=1e-9)
    assert E.wasserstein(a, b) == pytest.approx(math.sqrt(w2), rel=1e-9)
    S = 0.5 * (S1 + S2)
    d = m1 - m2
    bh = d @ np.linalg.solve(S, d) / 8 + 0.5 * math.log(np.linalg.det(S) / math.sqrt(np.linalg.det(S1) * np.linalg.det(S2)))
    assert E.bhattacharyya(a, b) == pytest.approx(bh, rel=1e-9)
    # IoU against counting the points of a fine grid.
    xs, ys = np.meshgrid(np.linspace(40, 170, 1301), np.linspace(20, 150, 1301))
    p = np.stack([xs.ravel(), ys.ravel()], 1)

    def inside(m, S):
        return np.einsum("ij,jk,ik->i", p - m, np.linalg.inv(S), p - m) <= 1

    ia, ib = inside(m1, S1), inside(m2, S2)
    assert E.iou(a, b) == pytest.approx((ia & ib).sum() / (ia | ib).sum(), abs=3e-3)
    assert E.level_set_distance(a, a) == pytest.approx(0.0, abs=1e-9)
    assert E.level_set_distance(a, b) > 0
    assert E.box_iou(E.Box(0, 0, 2, 2), E.Box(1, 0, 3, 2)) == pytest.approx(1 / 3)


def test_pose_conventions():
    rng = np.random.default_rng(2)
    R, t = rotation(rng), rng.normal(size=3)
    pose = E.Pose(R, t)
    np.testing.assert_allclose(pose.T_cw @ pose.T_wc, np.eye(4), atol=1e-12)
    np.testing.assert_allclose(pose.center, -R.T @ t)
    np.testing.assert_allclose(E.Pose.from_T_wc(pose.T_wc).T_cw, pose.T_cw, atol=1e-12)
    np.testing.assert_allclose(E.Pose.from_T_cw(pose.T_cw).R_cw, R)
    X = rng.normal(size=(5, 3))
    np.testing.assert_allclose(pose.transform(X), X @ R.T + t)
    np.testing.assert_allclose((pose * pose.inverse()).T_cw, np.eye(4), atol=1e-12)
    assert pickle.loads(pickle.dumps(pose)).T_cw.tolist() == pose.T_cw.tolist()
    with pytest.raises(ValueError, match="R_cw: is not a rotation"):
        E.Pose(2 * R, t)
    with pytest.raises(ValueError, match="last row"):
        E.Pose.from_T_wc(np.ones((4, 4)))


def test_p3p_recovers_the_pose():
    rng = np.random.default_rng(3)
    truth = E.Pose(rotation(rng), [0.1, -0.2, 3.0])
    X = rng.uniform(-1, 1, size=(3, 3))
    bearings = truth.transform(X)
    poses = E.p3p(bearings * 7.0, X)  # any length: normalised
    errors = [E.pose_error(p, truth) for p in poses]
    assert min(e.position_cm for e in errors) < 1e-6
    assert E.p3p(bearings, np.zeros((3, 3))) == []


def test_evaluation_rows():
    truth = E.Pose.look_at([1, 0, 1], [0, 0, 0])
    moved = E.Pose.look_at([1, 0.2, 1], [0, 0, 0])
    err = E.pose_error(moved, truth)
    assert err.position_cm == pytest.approx(20.0) and err.valid
    s = E.summarize([err, None, E.pose_error(E.Pose.look_at([3, 0, 1], [0, 0, 0]), truth)])
    assert (s.frames, s.relocalized, s.valid) == (3, 2, 1)
    assert s.valid_percent == pytest.approx(100 / 3)
    assert s.median_position_cm == pytest.approx(20.0)


def test_bad_arrays_name_the_argument():
    with pytest.raises(ValueError, match=r"center: expected shape \(2,\), got a float64 array of shape \(3,\)"):
        E.Ellipse(np.zeros(3), [1, 1])
    with pytest.raises(ValueError, match="axes: expected numbers, got a str"):
        E.Ellipse([0, 0], "ab")
    with pytest.raises(ValueError, match="axes: semi-axes must be positive"):
        E.Ellipse([0, 0], [1, -1])
    with pytest.raises(ValueError, match="center: contains a value that is not finite"):
        E.Ellipsoid([0, np.nan, 0], [1, 1, 1])
    with pytest.raises(ValueError, match=r"rotation: expected shape \(3, 3\)"):
        E.Ellipsoid([0, 0, 0], [1, 1, 1], np.eye(4))
    with pytest.raises(ValueError, match="Intrinsics"):
        E.Intrinsics(-1, 1, 0, 0, 10, 10)
    with pytest.raises(ValueError, match="expected numbers, got a object array"):
        E.Ellipse(np.array([None, None]), [1, 1])
