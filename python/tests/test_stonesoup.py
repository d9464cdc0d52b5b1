"""`scatterloc.stonesoup.BistaticDelayModel` in Stone Soup: its EKF track (Stone Soup's
`ExtendedKalmanPredictor` + `ExtendedKalmanUpdater`) equals `scatterloc.track` to 1e-8 with a
fixed and with a link-budget sigma, over several noise seeds; `function` against the closed form
(E1), `jacobian` against central finite differences, several states at once, a model of some
links, `covar` and `logpdf`, and a UKF updater that tracks the walker.

`BistaticDelayDopplerModel` (delays then range rates, docs/doppler.md): `function` and
`jacobian` against the closed form (E1, E3, D1, D3), `sl.range_rates`, the delay model and
central differences; H^T R^-1 H against the core's `crlb_doppler` Fisher matrix (D7); Stone
Soup's `ExtendedKalmanUpdater` (standard and Joseph) against a numpy update; bad arguments
named."""

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


# --------------------------------------------------------------------------------------------
# BistaticDelayDopplerModel: delays and range rates (issue 42, docs/doppler.md D1-D7)

from scatterloc.stonesoup import BistaticDelayDopplerModel  # noqa: E402

SIGMA_RATE = 0.1


def closed_form(s: sl.Scenario, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The delays and range rates of every link and their Jacobian (2L, 4) in scatterloc's
    order [x, y, vx, vy], in closed form for nodes in the target plane: E1, E3, D1 and D3
    (d rdot / d r = sum over the link's nodes of (I - u u^T) v / d)."""
    r, v = x[:2], x[2:]
    tx, rx = s.transmitters, s.receivers
    z, hd, zr, hr = [], [], [], []
    for i, j in s.link_indices:
        rng_, grad, rate, drate = 0.0, np.zeros(2), 0.0, np.zeros(2)
        for node in (tx[i], rx[j]):
            d = np.linalg.norm(r - node)
            u = (r - node) / d
            rng_ += d
            grad += u
            rate += u @ v
            drate += (v - u * (u @ v)) / d
        z.append(rng_ / C)
        hd.append(np.concatenate([grad / C, [0.0, 0.0]]))
        zr.append(rate)
        hr.append(np.concatenate([drate, grad]))
    return np.array(z + zr), np.array(hd + hr)


def random_states(rng: np.random.Generator, n: int) -> np.ndarray:
    """States [x, y, vx, vy] over sensors2019's area, at least 1 m from every node."""
    out = []
    while len(out) < n:
        x = np.array([rng.uniform(-7.5, 30), rng.uniform(-10, 26), rng.normal(0, 1.5), rng.normal(0, 1.5)])
        s = sl.Scenario.preset("sensors2019")
        nodes = np.concatenate([s.transmitters, s.receivers])
        if np.linalg.norm(nodes - x[:2], axis=1).min() > 1.0:
            out.append(x)
    return np.array(out)


def doppler_sigmas(s: sl.Scenario, p: np.ndarray, n: int = 16, **cpi) -> np.ndarray:
    """The default R's sigmas at position p: the link budget's delay sigma over sqrt(N), the
    CPI's range-rate sigma (D5)."""
    return np.concatenate([s.sigma_delays(p) / np.sqrt(n), sl.sigma_range_rates(s, p, cpi=n, **cpi)])


@pytest.mark.parametrize(
    "delay_links, rate_links", [(None, None), ([0, 2], [3, 1]), ([], [0, 1, 2]), ([1], [])]
)
def test_doppler_function_closed_form(s, delay_links, rate_links):
    """The delays then the range rates: the closed form (1e-12), `Scenario.delays`, the delay
    model's `function` and `sl.range_rates` (bit for bit), one state and several."""
    dl = list(range(4)) if delay_links is None else delay_links
    rl = list(range(4)) if rate_links is None else rate_links
    model = BistaticDelayDopplerModel(scenario=s, sigma=SIGMA, sigma_range_rate=SIGMA_RATE,
                                      delay_links=delay_links, rate_links=rate_links)
    assert model.ndim_meas == len(dl) + len(rl)
    xs = random_states(np.random.default_rng(7), 6)
    for x in xs:
        z = model.function(State(StateVector(x[PERM])))
        assert isinstance(z, StateVector) and z.shape == (len(dl) + len(rl), 1)
        z = np.asarray(z, dtype=float).ravel()
        want, _ = closed_form(s, x)
        np.testing.assert_allclose(z, np.concatenate([want[:4][dl], want[4:][rl]]), rtol=1e-12, atol=1e-15)
        np.testing.assert_array_equal(z[: len(dl)], s.delays(x[:2])[dl])
        if dl:
            delay_model = BistaticDelayModel(scenario=s, sigma=SIGMA, links=dl)
            np.testing.assert_array_equal(
                z[: len(dl)], np.asarray(delay_model.function(StateVector(x[PERM])), dtype=float).ravel()
            )
        np.testing.assert_array_equal(z[len(dl):], sl.range_rates(s, x)[0][rl])
    many = model.function(StateVectors(xs[:, PERM].T))
    assert isinstance(many, StateVectors) and many.shape == (len(dl) + len(rl), 6)
    for k, x in enumerate(xs):
        np.testing.assert_array_equal(
            np.asarray(many[:, k], dtype=float).ravel(),
            np.asarray(model.function(StateVector(x[PERM])), dtype=float).ravel(),
        )


@pytest.mark.parametrize("delay_links, rate_links", [(None, None), ([3, 0], [2])])
def test_doppler_jacobian(s, delay_links, rate_links):
    """The analytic Jacobian in Stone Soup's order: the closed form (1e-12), central
    differences of `function` (1e-6), the delay model's rows (bit for bit), zero velocity
    columns in the delay rows and c grad tau in the rate rows (D3)."""
    dl = list(range(4)) if delay_links is None else delay_links
    rl = list(range(4)) if rate_links is None else rate_links
    model = BistaticDelayDopplerModel(scenario=s, sigma=SIGMA, sigma_range_rate=SIGMA_RATE,
                                      delay_links=delay_links, rate_links=rate_links)
    for x in random_states(np.random.default_rng(8), 6):
        jac = model.jacobian(State(StateVector(x[PERM])))
        m = len(dl) + len(rl)
        assert jac.shape == (m, 4)
        _, h = closed_form(s, x)
        want = np.concatenate([h[:4][dl], h[4:][rl]])[:, PERM]
        scale = np.abs(want).max(axis=1, keepdims=True)
        assert (np.abs(jac - want) <= 1e-12 * scale).all()
        fd = np.zeros((m, 4))
        for c in range(4):
            e = np.zeros(4)
            e[c] = 1e-6
            up = np.asarray(model.function(StateVector(x[PERM] + e)), dtype=float).ravel()
            dn = np.asarray(model.function(StateVector(x[PERM] - e)), dtype=float).ravel()
            fd[:, c] = (up - dn) / 2e-6
        assert (np.abs(jac - fd) <= 1e-6 * scale).all(), np.abs(jac - fd).max()
        k = len(dl)
        assert (jac[:k, [1, 3]] == 0).all()
        np.testing.assert_array_equal(jac[:k], BistaticDelayModel(scenario=s, sigma=SIGMA, links=dl).jacobian(State(StateVector(x[PERM]))))
        np.testing.assert_allclose(jac[k:][:, [1, 3]], C * s.delay_jacobian(x[:2])[rl], rtol=1e-12)


def test_doppler_mapping_places_the_columns(s):
    """A state [vx, x, pad, vy, y] with mapping (1, 4) and velocity_mapping (0, 3): the same
    measurement and the Jacobian's columns moved."""
    x = np.array([6.0, 3.0, 0.7, -0.4])
    std = BistaticDelayDopplerModel(scenario=s, sigma=SIGMA, sigma_range_rate=SIGMA_RATE)
    odd = BistaticDelayDopplerModel(scenario=s, sigma=SIGMA, sigma_range_rate=SIGMA_RATE,
                                    ndim_state=5, mapping=(1, 4), velocity_mapping=(0, 3))
    sv5 = StateVector([x[2], x[0], 99.0, x[3], x[1]])
    np.testing.assert_array_equal(np.asarray(odd.function(sv5)), np.asarray(std.function(StateVector(x[PERM]))))
    j4, j5 = std.jacobian(State(StateVector(x[PERM]))), odd.jacobian(State(sv5))
    np.testing.assert_array_equal(j5[:, [1, 4, 0, 3]], j4[:, [0, 2, 1, 3]])
    assert (j5[:, 2] == 0).all()


@pytest.mark.parametrize("n, t, floor", [(16, 2.048e-3, 0.1), (4, 0.05, 0.0), (64, 1e-3, 0.3)])
def test_doppler_fisher_is_crlb_doppler_fim(s, n, t, floor):
    """With the link budget's delay sigma and the CPI's range-rate sigma, H^T R^-1 H at a
    state is the core's state Fisher matrix (D7, `crlb_doppler`'s `fim`), to 1e-12 of its
    blocks' scales."""
    model = BistaticDelayDopplerModel(scenario=s, cpi=n, cpi_spacing_s=t, range_rate_floor=floor)
    assert model.noise_covar is None
    for x in random_states(np.random.default_rng(9), 5):
        h = model.jacobian(State(StateVector(x[PERM])))
        r = np.asarray(model.covar(), dtype=float)
        f = (h.T @ np.linalg.solve(r, h))[np.ix_(PERM, PERM)]
        fim = np.array(sl.crlb_doppler(s, x[:2], x[2:], cpi=n, cpi_spacing_s=t, range_rate_floor=floor)["fim"])
        scale = np.sqrt(np.outer(np.diag(fim), np.diag(fim)))
        assert (np.abs(f - fim) <= 1e-12 * scale).all(), np.abs((f - fim) / scale).max()


def test_doppler_covar(s):
    x = np.array([8.0, 2.0, 0.5, -0.5])
    st = State(StateVector(x[PERM]))
    # Fixed: per part, one or one per link.
    fixed = BistaticDelayDopplerModel(scenario=s, sigma=[3e-11, 4e-11], sigma_range_rate=0.2,
                                      delay_links=[0, 2], rate_links=[1, 2, 3])
    want = np.diag(np.array([3e-11, 4e-11, 0.2, 0.2, 0.2]) ** 2)
    np.testing.assert_array_equal(np.asarray(fixed.covar()), want)
    np.testing.assert_array_equal(np.asarray(fixed.covar(state=st)), want)
    # State-dependent: needs a state; then the link budget over sqrt(N) and the CPI's (D5).
    model = BistaticDelayDopplerModel(scenario=s, cpi=8)
    with pytest.raises(sl.ScatterlocError) as e:
        model.covar()
    assert e.value.field == "state"
    sig = doppler_sigmas(s, x[:2], n=8)
    np.testing.assert_array_equal(np.asarray(model.covar(state=st)), np.diag(sig**2))
    model.jacobian(st)
    np.testing.assert_array_equal(np.asarray(model.covar()), np.diag(sig**2))
    # One part fixed, the other from the state.
    mixed = BistaticDelayDopplerModel(scenario=s, sigma=SIGMA, cpi=8)
    np.testing.assert_array_equal(
        np.asarray(mixed.covar(state=st)), np.diag(np.concatenate([np.full(4, SIGMA), sig[4:]]) ** 2)
    )
    mixed2 = BistaticDelayDopplerModel(scenario=s, sigma_range_rate=0.3, cpi=1)
    np.testing.assert_array_equal(
        np.asarray(mixed2.covar(state=st)), np.diag(np.concatenate([s.sigma_delays(x[:2]), np.full(4, 0.3)]) ** 2)
    )


def test_doppler_logpdf_closed_form(s):
    x = np.array([7.0, 4.0, 1.0, 0.0])
    st = State(StateVector(x[PERM]))
    rng = np.random.default_rng(4)
    for kw in (dict(sigma=SIGMA, sigma_range_rate=SIGMA_RATE), dict()):
        model = BistaticDelayDopplerModel(scenario=s, **kw)
        sig = np.concatenate([np.full(4, SIGMA), np.full(4, SIGMA_RATE)]) if kw else doppler_sigmas(s, x[:2])
        mean, _ = closed_form(s, x)
        z = mean + sig * rng.standard_normal(8)
        want = -0.5 * np.sum(((z - mean) / sig) ** 2 + np.log(2 * np.pi * sig**2))
        assert model.logpdf(State(StateVector(z)), st) == pytest.approx(want, rel=1e-12)


def reference_update(x, p, z, h_of, r, joseph):
    """One EKF update written out in numpy (scatterloc's order): the closed-form h and H at the
    prior mean, K = P H^T S^-1 (S scaled to a unit diagonal before the solve), and the
    standard or Joseph covariance."""
    hx, hh = h_of(x)
    s_ = hh @ p @ hh.T + r
    d = np.sqrt(np.diag(s_))
    k = np.linalg.solve(s_ / np.outer(d, d), (hh @ p / d[:, None])).T / d[None, :]
    xp = x + k @ (z - hx)
    if joseph:
        ikh = np.eye(4) - k @ hh
        pp = ikh @ p @ ikh.T + k @ r @ k.T
    else:
        pp = p - k @ s_ @ k.T
    return xp, pp


@pytest.mark.parametrize("joseph", [False, True], ids=["standard", "joseph"])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_doppler_ekf_update_equals_reference(s, seed, joseph):
    """Stone Soup's ExtendedKalmanUpdater with the model equals the numpy update (state and
    covariance to 1e-9 of their scales), with fixed sigmas and with the link budget's and the
    CPI's. The range rates measure the velocity: the delay model's update leaves the velocity
    covariance of a prior without position-velocity correlation exactly as it was, the
    Doppler model's shrinks it to the reference's numbers, which are also the information
    form's (P^-1 + H^T R^-1 H)^-1."""
    rng = np.random.default_rng(seed)
    truth = random_states(rng, 1)[0]
    p0 = np.diag([0.05, 0.05, 0.25, 0.25])
    x0 = truth + rng.multivariate_normal(np.zeros(4), p0)
    prior = GaussianState(StateVector(x0[PERM]), p0[np.ix_(PERM, PERM)], timestamp=T0)
    for kw in (dict(sigma=SIGMA, sigma_range_rate=SIGMA_RATE), dict()):
        model = BistaticDelayDopplerModel(scenario=s, **kw)
        sig = (np.concatenate([np.full(4, SIGMA), np.full(4, SIGMA_RATE)]) if kw
               else doppler_sigmas(s, x0[:2]))
        r = np.diag(sig**2)
        z = closed_form(s, truth)[0] + sig * rng.standard_normal(8)
        det = Detection(StateVector(z), timestamp=T0, measurement_model=model)
        post = ExtendedKalmanUpdater(model, use_joseph_cov=joseph).update(SingleHypothesis(prior, det))
        xs = np.asarray(post.state_vector, dtype=float).ravel()[PERM]
        ps = np.asarray(post.covar, dtype=float)[np.ix_(PERM, PERM)]
        xr, pr = reference_update(x0, p0, z, lambda x: closed_form(s, x), r, joseph)
        assert np.abs(xs - xr).max() <= 1e-9 * np.abs(xr).max()
        scale = np.sqrt(np.outer(np.diag(pr), np.diag(pr)))
        if joseph:
            assert (np.abs(ps - pr) <= 1e-9 * scale).all(), np.abs((ps - pr) / scale).max()
        else:
            # The standard form P - K S K^T cancels: with the link budget's sigma over 16
            # snapshots, a 0.05 m^2 prior falls to 1.6e-7 m^2 (seed 2), and Stone Soup's
            # np.linalg.inv of the unscaled S (entries 1e-22 s^2 to 1e-2 m^2/s^2) leaves
            # 1.5e-12 m^2 there: 1e-5 of the posterior, 3e-11 of the prior (the reference's
            # scaled solve and the Joseph form agree to 2e-11 and 4e-16). To 1e-9 of the prior.
            pscale = np.sqrt(np.outer(np.diag(p0), np.diag(p0)))
            assert (np.abs(ps - pr) <= 1e-9 * pscale).all(), np.abs((ps - pr) / pscale).max()
        # The information form of the same update.
        _, hh = closed_form(s, x0)
        pinf = np.linalg.inv(np.linalg.inv(p0) + hh.T @ np.diag(1 / sig**2) @ hh)
        assert (np.abs(pinf - pr) <= 1e-9 * scale).all()
        # Velocity: the reference's posterior block, well below the prior's (the rates'
        # sigma ~0.1 m/s against the prior's 0.5 m/s).
        np.testing.assert_allclose(ps[2:, 2:], pr[2:, 2:], rtol=1e-9, atol=0)
        assert np.trace(pr[2:, 2:]) < 0.2 * np.trace(p0[2:, 2:])
        # The delays alone (the same delay sigmas) leave it unchanged.
        delay_model = BistaticDelayModel(scenario=s, sigma=sig[:4])
        d_det = Detection(StateVector(z[:4]), timestamp=T0, measurement_model=delay_model)
        d_post = ExtendedKalmanUpdater(delay_model, use_joseph_cov=joseph).update(SingleHypothesis(prior, d_det))
        pd = np.asarray(d_post.covar, dtype=float)[np.ix_(PERM, PERM)]
        xd, pdr = reference_update(x0, p0, z[:4], lambda x: tuple(a[:4] for a in closed_form(s, x)), r[:4, :4], joseph)
        np.testing.assert_allclose(pd[2:, 2:], p0[2:, 2:], rtol=1e-12, atol=0)
        np.testing.assert_allclose(pdr[2:, 2:], p0[2:, 2:], rtol=1e-12, atol=0)
        # Both bound the position alike; the Doppler update's position is no worse.
        assert np.trace(pr[:2, :2]) <= np.trace(pdr[:2, :2]) * (1 + 1e-9)


@pytest.mark.parametrize(
    "kw, field",
    [
        (dict(sigma=0.0), "sigma"),
        (dict(sigma=[SIGMA] * 3), "sigma"),
        (dict(sigma_range_rate=-0.1), "sigma_range_rate"),
        (dict(sigma_range_rate=float("nan")), "sigma_range_rate"),
        (dict(sigma_range_rate=[0.1, 0.1], rate_links=[0, 1, 2]), "sigma_range_rate"),
        (dict(delay_links=[0, 4]), "delay_links"),
        (dict(rate_links=[1, 1]), "rate_links"),
        (dict(rate_links=[-1]), "rate_links"),
        (dict(delay_links=[], rate_links=[]), "rate_links"),
        (dict(mapping=(0, 1)), "velocity_mapping"),
        (dict(velocity_mapping=(1, 4)), "velocity_mapping"),
        (dict(velocity_mapping=(1, 3, 5)), "velocity_mapping"),
        (dict(cpi=1), "cpi.snapshots"),
        (dict(cpi=0, sigma_range_rate=0.1), "cpi.snapshots"),
        (dict(cpi=-3), "cpi.snapshots"),
        (dict(cpi=16.5), "cpi.snapshots"),
        (dict(cpi_spacing_s=0.0), "cpi.spacing_s"),
        (dict(range_rate_floor=-1.0), "cpi.floor_mps"),
        (dict(noise_covar=np.eye(8)), "noise_covar"),
    ],
)
def test_doppler_bad_model_arguments_are_named(s, kw, field):
    with pytest.raises(sl.ScatterlocError) as e:
        BistaticDelayDopplerModel(scenario=s, **kw)
    assert e.value.field == field, (e.value.field, str(e.value))


def test_doppler_bad_states_are_named(s):
    model = BistaticDelayDopplerModel(scenario=s, sigma=SIGMA, sigma_range_rate=SIGMA_RATE)
    with pytest.raises(sl.ScatterlocError) as e:
        model.function(StateVector([np.nan, 0.0, 1.0, 0.0]))
    assert e.value.field is not None and e.value.field.startswith(("points", "states"))
    with pytest.raises(sl.ScatterlocError) as e:
        model.function(StateVector([1.0, 2e6, 1.0, 0.0]))
    assert e.value.field == "states[0][2]"
    with pytest.raises(sl.ScatterlocError) as e:
        model.jacobian(StateVectors(np.zeros((4, 2))))
    assert e.value.field == "state"
