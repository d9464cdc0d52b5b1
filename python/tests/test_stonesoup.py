"""`scatterloc.stonesoup.BistaticDelayModel` in Stone Soup: its EKF track (Stone Soup's
`ExtendedKalmanPredictor` + `ExtendedKalmanUpdater`) equals `scatterloc.track` to 1e-8 with a
fixed and with a link-budget sigma, over several noise seeds; `function` against the closed form
(E1), `jacobian` against central finite differences, several states at once, a model of some
links, `covar` and `logpdf`, and a UKF updater that tracks the walker."""

from __future__ import annotations

import datetime

import numpy as np
import pytest

pytest.importorskip("stonesoup")

from stonesoup.models.transition.linear import (  # noqa: E402
    CombinedLinearGaussianTransitionModel,
    ConstantVelocity,
)
from stonesoup.predictor.kalman import ExtendedKalmanPredictor  # noqa: E402
from stonesoup.types.array import StateVector, StateVectors  # noqa: E402
from stonesoup.types.detection import Detection  # noqa: E402
from stonesoup.types.hypothesis import SingleHypothesis  # noqa: E402
from stonesoup.types.state import GaussianState, State  # noqa: E402
from stonesoup.updater.kalman import ExtendedKalmanUpdater, UnscentedKalmanUpdater  # noqa: E402

import scatterloc as sl  # noqa: E402
from scatterloc.stonesoup import BistaticDelayModel  # noqa: E402

C = 299_792_458.0
DT = 0.1
Q = 0.01
STEPS = 50
X0 = np.array([4.0, 1.0, 1.39, 0.25])  # scatterloc's order [x, y, vx, vy]
P0 = np.diag([0.1, 0.1, 0.01, 0.01])
SIGMA = 3.5e-11
# Stone Soup's constant-velocity order [x, vx, y, vy] from scatterloc's [x, y, vx, vy]; the
# permutation is its own inverse.
PERM = [0, 2, 1, 3]
T0 = datetime.datetime(2024, 1, 1)


@pytest.fixture(scope="module")
def s() -> sl.Scenario:
    return sl.Scenario.preset("sensors2019")


def truth_positions() -> np.ndarray:
    """Constant velocity from X0: the positions at t = DT, 2 DT, ..., STEPS DT."""
    t = DT * np.arange(1, STEPS + 1)
    return X0[:2] + t[:, None] * X0[2:]


def noisy_delays(s: sl.Scenario, seed: int) -> tuple[np.ndarray, np.ndarray]:
    truth = truth_positions()
    rng = np.random.default_rng(seed)
    d = s.delays(truth) + rng.standard_normal((STEPS, s.link_count)) * s.sigma_delays(truth)
    return truth, d


def ss_state(x: np.ndarray) -> np.ndarray:
    return np.asarray(x, dtype=float)[PERM]


def stonesoup_track(model, delays: np.ndarray, updater_cls=ExtendedKalmanUpdater, **updater_kw):
    """Stone Soup's filter over ``delays`` (rows of the model's measured links): step k
    predicts by DT and updates with row k. Returns states (K, 4) and covariances (K, 4, 4) in
    scatterloc's order."""
    predictor = ExtendedKalmanPredictor(
        CombinedLinearGaussianTransitionModel([ConstantVelocity(Q), ConstantVelocity(Q)])
    )
    updater = updater_cls(model, **updater_kw)
    state = GaussianState(ss_state(X0)[:, None], P0[np.ix_(PERM, PERM)], timestamp=T0)
    states, covs = [], []
    for k, z in enumerate(delays):
        ts = T0 + datetime.timedelta(seconds=DT * (k + 1))
        prediction = predictor.predict(state, timestamp=ts)
        det = Detection(np.asarray(z, dtype=float)[:, None], timestamp=ts, measurement_model=model)
        state = updater.update(SingleHypothesis(prediction, det))
        states.append(np.asarray(state.state_vector, dtype=float).ravel()[PERM])
        covs.append(np.asarray(state.covar, dtype=float)[np.ix_(PERM, PERM)])
    return np.array(states), np.array(covs)


def assert_track_close(states, covs, ref) -> None:
    """States to 1e-8 absolute (m, m/s); covariances to 1e-8 relative (to each matrix's
    largest entry)."""
    assert states.shape == ref.states.shape and covs.shape == ref.covariances.shape
    np.testing.assert_allclose(states, ref.states, rtol=0, atol=1e-8)
    scale = np.abs(ref.covariances).max(axis=(1, 2))
    err = np.abs(covs - ref.covariances).max(axis=(1, 2))
    assert (err <= 1e-8 * scale).all(), (err / scale).max()


# --------------------------------------------------------------------------------------------
# The EKF in Stone Soup equals scatterloc's


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("sigma", [SIGMA, None], ids=["fixed", "budget"])
def test_ekf_equals_scatterloc_track(s, seed, sigma):
    truth, delays = noisy_delays(s, seed)
    ref = sl.track(
        s, delays, dt=DT, process_noise=Q, initial_state=X0, initial_covariance=P0, sigma=sigma
    )
    np.testing.assert_allclose(ref.t, DT * np.arange(1, STEPS + 1), rtol=1e-12)
    model = BistaticDelayModel(scenario=s, sigma=sigma)
    states, covs = stonesoup_track(model, delays)
    assert_track_close(states, covs, ref)
    # And both follow the walker (the [S] layout's bound is a few cm here).
    assert np.abs(states[:, :2] - truth).max() < 0.1


@pytest.mark.parametrize("seed", [4, 5, 6])
def test_ekf_per_link_sigma_and_scenario_dict(s, seed):
    """A per-link sigma, and the model built from the scenario's dict."""
    sig = np.array([3e-11, 4e-11, 5e-11, 6e-11])
    _, delays = noisy_delays(s, seed)
    ref = sl.track(s, delays, dt=DT, process_noise=Q, initial_state=X0, initial_covariance=P0, sigma=sig)
    model = BistaticDelayModel(scenario=s.to_dict(), sigma=list(sig))
    assert isinstance(model.scenario, sl.Scenario) and model.scenario == s
    np.testing.assert_array_equal(np.asarray(model.covar()), np.diag(sig**2))
    states, covs = stonesoup_track(model, delays)
    assert_track_close(states, covs, ref)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_ekf_some_links_equals_track_with_missing_links(s, seed):
    """A model of links 0 and 2 equals scatterloc's track with links 1 and 3 missing (NaN)."""
    _, delays = noisy_delays(s, seed)
    partial = delays.copy()
    partial[:, [1, 3]] = np.nan
    for sigma in (SIGMA, None):
        ref = sl.track(
            s, partial, dt=DT, process_noise=Q, initial_state=X0, initial_covariance=P0, sigma=sigma
        )
        assert (ref.links_used == 2).all()
        model = BistaticDelayModel(scenario=s, sigma=sigma, links=[0, 2])
        states, covs = stonesoup_track(model, delays[:, [0, 2]])
        assert_track_close(states, covs, ref)


# --------------------------------------------------------------------------------------------
# function, jacobian, covar


def test_function_closed_form(s):
    model = BistaticDelayModel(scenario=s, sigma=SIGMA)
    assert model.ndim_meas == 4 and model.ndim_state == 4
    tx, rx = s.transmitters, s.receivers
    rng = np.random.default_rng(11)
    for _ in range(5):
        p = rng.uniform([-7.5, -10], [30, 26])
        x = np.array([p[0], rng.normal(), p[1], rng.normal()])
        z = model.function(State(StateVector(x)))
        assert isinstance(z, StateVector) and z.shape == (4, 1)
        want = [(np.linalg.norm(p - tx[i]) + np.linalg.norm(p - rx[j])) / C for i, j in s.link_indices]
        np.testing.assert_allclose(np.asarray(z, dtype=float).ravel(), want, rtol=1e-14, atol=0)
        # A state vector (not a State) works too; the velocity does not matter.
        x2 = x.copy()
        x2[[1, 3]] += 5.0
        np.testing.assert_array_equal(np.asarray(model.function(StateVector(x2))), np.asarray(z))


def test_function_on_state_vectors(s):
    model = BistaticDelayModel(scenario=s, sigma=SIGMA)
    rng = np.random.default_rng(3)
    xs = np.stack([rng.uniform(-5, 25, 7), rng.normal(size=7), rng.uniform(-8, 20, 7), rng.normal(size=7)])
    z = model.function(StateVectors(xs))
    assert isinstance(z, StateVectors) and z.shape == (4, 7)
    for k in range(7):
        one = model.function(StateVector(xs[:, k]))
        np.testing.assert_array_equal(np.asarray(z[:, k : k + 1], dtype=float), np.asarray(one, dtype=float))
    np.testing.assert_array_equal(
        np.asarray(z, dtype=float), s.delays(np.ascontiguousarray(xs[[0, 2]].T)).T
    )


@pytest.mark.parametrize("links", [None, [0, 2], [3, 1]])
def test_jacobian_central_differences(s, links):
    model = BistaticDelayModel(scenario=s, sigma=SIGMA, links=links)
    sel = list(range(4)) if links is None else links
    rng = np.random.default_rng(5)
    h = 1e-3
    for _ in range(5):
        x = np.array([rng.uniform(-5, 25), rng.normal(), rng.uniform(-8, 20), rng.normal()])
        jac = model.jacobian(State(StateVector(x)))
        assert jac.shape == (len(sel), 4)
        fd = np.zeros((len(sel), 4))
        for c in range(4):
            e = np.zeros(4)
            e[c] = h
            up = np.asarray(model.function(StateVector(x + e)), dtype=float).ravel()
            dn = np.asarray(model.function(StateVector(x - e)), dtype=float).ravel()
            fd[:, c] = (up - dn) / (2 * h)
        # Velocity columns are exactly zero; position columns match to 1e-6 relative.
        assert (jac[:, [1, 3]] == 0).all() and (fd[:, [1, 3]] == 0).all()
        np.testing.assert_allclose(jac[:, [0, 2]], fd[:, [0, 2]], rtol=1e-6, atol=0)
        # E3 in closed form: the sum of the unit vectors from Tx and Rx, over c.
        p = x[[0, 2]]
        tx, rx = s.transmitters, s.receivers
        g = []
        for li in sel:
            i, j = s.link_indices[li]
            g.append(((p - tx[i]) / np.linalg.norm(p - tx[i]) + (p - rx[j]) / np.linalg.norm(p - rx[j])) / C)
        np.testing.assert_allclose(jac[:, [0, 2]], np.array(g), rtol=1e-12, atol=0)


def test_links_model(s):
    model = BistaticDelayModel(scenario=s, sigma=[3e-11, 7e-11], links=[0, 2])
    assert model.ndim_meas == 2
    x = StateVector([6.0, 1.0, 3.0, 0.0])
    z = np.asarray(model.function(State(x)), dtype=float).ravel()
    np.testing.assert_array_equal(z, s.delays([6.0, 3.0])[[0, 2]])
    np.testing.assert_array_equal(
        model.jacobian(State(x))[:, [0, 2]], s.delay_jacobian([6.0, 3.0])[[0, 2]]
    )
    np.testing.assert_array_equal(np.asarray(model.covar()), np.diag([9e-22, 49e-22]))
    with pytest.raises(sl.ScatterlocError):
        BistaticDelayModel(scenario=s, sigma=SIGMA, links=[0, 4])
    with pytest.raises(sl.ScatterlocError):
        BistaticDelayModel(scenario=s, sigma=SIGMA, links=[1, 1])
    with pytest.raises(ValueError):
        BistaticDelayModel(scenario=s, sigma=[SIGMA] * 3, links=[0, 2])


def test_sigma_of_wrong_length_is_named(s):
    with pytest.raises(sl.ScatterlocError) as e:
        BistaticDelayModel(scenario=s, sigma=[SIGMA] * 3, links=[0, 2])
    assert str(e.value).startswith("sigma")


def test_covar_link_budget(s):
    model = BistaticDelayModel(scenario=s, sigma=None)
    # No linearisation state yet: R cannot be built.
    with pytest.raises(sl.ScatterlocError):
        model.covar()
    assert issubclass(sl.ScatterlocError, ValueError)
    x = StateVector([8.0, 0.5, 2.0, -0.5])
    # covar(state=...) is the link budget's sigma^2 at that state (E8) ...
    want = np.diag(s.sigma_delays([8.0, 2.0]) ** 2)
    np.testing.assert_array_equal(np.asarray(model.covar(state=State(x))), want)
    # ... and after a jacobian, at the linearisation state.
    model.jacobian(State(x))
    np.testing.assert_array_equal(np.asarray(model.covar()), want)
    model.jacobian(State(StateVector([12.0, 0.0, 5.0, 0.0])))
    np.testing.assert_array_equal(np.asarray(model.covar()), np.diag(s.sigma_delays([12.0, 5.0]) ** 2))
    # A fixed sigma ignores the state.
    fixed = BistaticDelayModel(scenario=s, sigma=SIGMA)
    np.testing.assert_array_equal(np.asarray(fixed.covar()), SIGMA**2 * np.eye(4))
    np.testing.assert_array_equal(np.asarray(fixed.covar(state=State(x))), SIGMA**2 * np.eye(4))


@pytest.mark.parametrize("kw", [dict(sigma=0.0), dict(sigma=-1e-11), dict(sigma=float("nan")), dict(noise_covar=np.eye(4))])
def test_bad_model_arguments(s, kw):
    with pytest.raises(sl.ScatterlocError):
        BistaticDelayModel(scenario=s, **kw)


def test_logpdf_closed_form(s):
    """The Gaussian log-likelihood with R = diag(sigma^2): fixed, and the link budget's at the
    state."""
    x = State(StateVector([7.0, 1.0, 4.0, 0.0]))
    rng = np.random.default_rng(2)
    for sigma in (SIGMA, None):
        model = BistaticDelayModel(scenario=s, sigma=sigma)
        sig = np.full(4, SIGMA) if sigma is not None else s.sigma_delays([7.0, 4.0])
        mean = s.delays([7.0, 4.0])
        z = mean + sig * rng.standard_normal(4)
        want = -0.5 * np.sum(((z - mean) / sig) ** 2 + np.log(2 * np.pi * sig**2))
        got = model.logpdf(State(StateVector(z)), x)
        assert got == pytest.approx(want, rel=1e-12)
        assert model.pdf(State(StateVector(z)), x) == pytest.approx(np.exp(want), rel=1e-10)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_rvs_covariance(s, seed):
    """Noise samples have covariance R (within sampling error, 4 sigma of the variance's
    estimate)."""
    np.random.seed(seed)
    model = BistaticDelayModel(scenario=s, sigma=[3e-11, 4e-11, 5e-11, 6e-11])
    n = 20000
    w = np.asarray(model.rvs(num_samples=n), dtype=float)
    assert w.shape == (4, n)
    var = w.var(axis=1)
    want = np.array([3e-11, 4e-11, 5e-11, 6e-11]) ** 2
    assert np.all(np.abs(var / want - 1) < 4 * np.sqrt(2 / n))
    assert np.abs(np.mean(w, axis=1) / np.sqrt(want)).max() < 4 / np.sqrt(n)


# --------------------------------------------------------------------------------------------
# The UKF updater


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_ukf_updater_tracks(s, seed):
    truth, delays = noisy_delays(s, seed)
    model = BistaticDelayModel(scenario=s, sigma=SIGMA)
    states, covs = stonesoup_track(model, delays, UnscentedKalmanUpdater)
    err = np.linalg.norm(states[:, :2] - truth, axis=1)
    assert err.max() < 0.05, err.max()
    assert np.isfinite(covs).all()
    assert (np.linalg.eigvalsh(covs) > 0).all()
    # Close to the EKF: the delays are near-linear over the posterior's few cm.
    ekf = sl.track(s, delays, dt=DT, process_noise=Q, initial_state=X0, initial_covariance=P0, sigma=SIGMA)
    assert np.abs(states[:, :2] - ekf.states[:, :2]).max() < 0.01
    # With the same (alpha, beta, kappa) as scatterloc's UKF: the same track up to the sigma
    # points' matrix square root (both take the lower Cholesky factor, but of P in their own
    # state order, [x, vx, y, vy] vs [x, y, vx, vy]: a different factor, so the unscented sums
    # differ in third-order terms, ~5e-7 relative on P, a few 1e-8 m on the state; the next
    # test takes the same factor and gets 1e-8).
    for alpha in (1.0, 0.5):
        ref = sl.track(
            s, delays, dt=DT, process_noise=Q, initial_state=X0, initial_covariance=P0,
            sigma=SIGMA, filter="ukf", ukf_alpha=alpha, ukf_beta=2.0, ukf_kappa=0.0,
        )
        st, cv = stonesoup_track(model, delays, UnscentedKalmanUpdater, alpha=alpha, beta=2.0, kappa=0.0)
        np.testing.assert_allclose(st, ref.states, rtol=0, atol=2e-7)
        scale = np.abs(ref.covariances).max(axis=(1, 2))
        assert (np.abs(cv - ref.covariances).max(axis=(1, 2)) <= 2e-6 * scale).all()


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("alpha", [1.0, 0.5])
def test_ukf_updater_equals_scatterloc_ukf(s, seed, alpha, monkeypatch):
    """Stone Soup's UKF updater with the sigma points of scatterloc's UKF (the lower Cholesky
    factor of P in [x, y, vx, vy] order, permuted to Stone Soup's order) equals
    ``track(filter="ukf")`` to 1e-8."""
    perm = np.eye(4)[PERM]
    cholesky = np.linalg.cholesky

    def scatterloc_order_cholesky(a, *args, **kwargs):
        a = np.asarray(a)
        if a.shape == (4, 4):
            return perm @ cholesky(perm.T @ a @ perm)
        return cholesky(a, *args, **kwargs)

    _, delays = noisy_delays(s, seed)
    ref = sl.track(
        s, delays, dt=DT, process_noise=Q, initial_state=X0, initial_covariance=P0,
        sigma=SIGMA, filter="ukf", ukf_alpha=alpha, ukf_beta=2.0, ukf_kappa=0.0,
    )
    model = BistaticDelayModel(scenario=s, sigma=SIGMA)
    monkeypatch.setattr(np.linalg, "cholesky", scatterloc_order_cholesky)
    states, covs = stonesoup_track(model, delays, UnscentedKalmanUpdater, alpha=alpha, beta=2.0, kappa=0.0)
    monkeypatch.undo()
    assert_track_close(states, covs, ref)
