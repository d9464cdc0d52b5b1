"""Stone Soup measurement model of bistatic delays (needs ``pip install scatterloc[stonesoup]``).

:class:`BistaticDelayModel` is a Stone Soup ``NonLinearGaussianMeasurement`` whose
``function`` (the delays, spec E1), ``jacobian`` (their gradient, E3) and ``covar`` (R: a fixed
delay sigma, or the link budget's, E8) come from the scatterloc core, so Stone Soup's own
``ExtendedKalmanUpdater``, ``UnscentedKalmanUpdater``, particle updaters, trackers, data
associators and metrics run on scatterloc's geometry. Stone Soup itself has monostatic
range/bearing models only.

State: Stone Soup's constant-velocity order ``[x, vx, y, vy]`` by default (``mapping=(0, 2)``:
the position components); measurement: one delay per link in the scenario's link order
(seconds), or the links ``links`` only (a detection whose other links are missing).

Example (the EKF of spec section 6 in Stone Soup)::

    from stonesoup.models.transition.linear import (
        CombinedLinearGaussianTransitionModel, ConstantVelocity)
    from stonesoup.predictor.kalman import ExtendedKalmanPredictor
    from stonesoup.updater.kalman import ExtendedKalmanUpdater
    import scatterloc as sl
    from scatterloc.stonesoup import BistaticDelayModel

    s = sl.Scenario.preset("sensors2019")
    model = BistaticDelayModel(scenario=s, sigma=3.5e-11)
    predictor = ExtendedKalmanPredictor(CombinedLinearGaussianTransitionModel(
        [ConstantVelocity(0.01), ConstantVelocity(0.01)]))
    updater = ExtendedKalmanUpdater(model)
"""

from __future__ import annotations

from typing import Any, Optional, Sequence, Union

import numpy as np

try:
    from stonesoup.base import Property
    from stonesoup.models.measurement.nonlinear import NonLinearGaussianMeasurement
    from stonesoup.types.array import CovarianceMatrix, StateVector, StateVectors
except ImportError as e:  # pragma: no cover - exercised only without Stone Soup
    raise ImportError(
        "scatterloc.stonesoup needs Stone Soup: pip install 'scatterloc[stonesoup]'"
    ) from e

from ._scatterloc import Scenario, ScatterlocError

__all__ = ["BistaticDelayModel"]


def _error(field: str, message: str) -> ScatterlocError:
    """A ScatterlocError naming ``field``, as the native functions raise them."""
    e = ScatterlocError(f"{field}: {message}")
    e.field = field
    e.kind = "InvalidArgument"
    return e


class BistaticDelayModel(NonLinearGaussianMeasurement):  # type: ignore[misc]
    r"""Bistatic propagation delays of a scatterer on a scatterloc scenario's links.

    For a state with position :math:`r = (x, y)` (the components ``mapping`` picks), the
    measurement is :math:`\tau_p(r) = (\lVert r - r^{Tx}_p\rVert + \lVert r - r^{Rx}_p\rVert)/c`
    per link :math:`p` (spec E1), its Jacobian :math:`\partial\tau_p/\partial r` (E3) placed in
    the ``mapping`` columns, and :math:`R = \mathrm{diag}(\sigma_p^2)` with either the fixed
    ``sigma`` (s, one for all links or one per link) or, when ``sigma`` is None, the link
    budget's :math:`\sigma_p(r)` (E8) at the linearisation state: the state of the latest
    ``jacobian`` call, which in Stone Soup's ``ExtendedKalmanUpdater`` is the predicted state
    (spec section 6's R at the prediction), or the ``state`` given to ``covar(state=...)``.
    Sampling and likelihoods use the same R.
    """

    scenario: Scenario = Property(doc="The scatterloc scenario (nodes, links, link budget).")
    sigma: Optional[Union[float, Sequence[float]]] = Property(
        default=None,
        doc="Delay standard deviation, s: one for every link or one per measured link. "
        "None: the link budget's (E8) at the linearisation state.",
    )
    links: Optional[Sequence[int]] = Property(
        default=None,
        doc="Indices of the scenario links this model measures, in measurement order "
        "(default: every link).",
    )
    ndim_state: int = Property(default=4, doc="Number of state dimensions.")
    mapping: Sequence[int] = Property(
        default=(0, 2), doc="The state components that are the position (x, y)."
    )
    noise_covar: CovarianceMatrix = Property(
        default=None, doc="Set from ``sigma``; do not give it."
    )

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        if args:
            raise TypeError(
                "BistaticDelayModel takes keyword arguments (scenario=..., sigma=..., links=...)"
            )
        scenario = kwargs.get("scenario")
        if scenario is None:
            raise _error("scenario", "required")
        if not isinstance(scenario, Scenario):
            kwargs["scenario"] = Scenario(scenario)
        if kwargs.get("noise_covar") is not None:
            raise _error("noise_covar", "set sigma instead (R is built from it)")
        # A placeholder until the real R is known (the parent converts it).
        kwargs["noise_covar"] = np.eye(1)
        super().__init__(*args, **kwargs)
        n = self.scenario.link_count
        links = list(range(n)) if self.links is None else [int(p) for p in self.links]
        for p in links:
            if not 0 <= p < n:
                raise _error("links", f"link {p} is not in 0..{n - 1}")
        if len(set(links)) != len(links) or not links:
            raise _error("links", "expected distinct link indices, at least one")
        self._links = np.asarray(links, dtype=np.intp)
        if len(self.mapping) != 2:
            raise _error("mapping", "expected the two position components (x, y)")
        self._linearisation: Optional[np.ndarray] = None
        if self.sigma is None:
            self.noise_covar = None
        else:
            s = np.asarray(self.sigma, dtype=float)
            if s.ndim > 1 or (s.ndim == 1 and s.size != len(links)):
                raise _error(
                    "sigma",
                    f"expected one delay sigma or {len(links)} (one per measured link), "
                    f"got shape {s.shape}",
                )
            s = np.broadcast_to(s, (len(links),))
            if not np.all(np.isfinite(s) & (s > 0)):
                raise _error("sigma", "every delay sigma must be a finite number > 0 s")
            self.noise_covar = CovarianceMatrix(np.diag(s**2))

    @property
    def ndim_meas(self) -> int:
        """Number of measured links."""
        return int(self._links.size)

    def _positions(self, state: Any) -> np.ndarray:
        """The positions (N, 2) of a state, its state vector or its state vectors."""
        sv = state.state_vector if hasattr(state, "state_vector") else state
        sv = np.asarray(sv, dtype=float)
        if sv.ndim == 1:
            sv = sv[:, None]
        return np.stack([sv[self.mapping[0], :], sv[self.mapping[1], :]], axis=1)

    def function(self, state: Any, noise: Any = False, **kwargs: Any) -> Union[StateVector, StateVectors]:
        """The delays (s) of the state's position on the measured links (E1)."""
        pos = self._positions(state)
        delays = self.scenario.delays(pos)[:, self._links].T  # (L, N)
        if isinstance(noise, bool) or noise is None:
            if noise:
                covar = self.covar(state=state) if self.sigma is None else self.noise_covar
                noise = np.random.multivariate_normal(
                    np.zeros(self.ndim_meas), covar, size=pos.shape[0]
                ).T
            else:
                noise = 0
        out = delays + noise
        if out.shape[1] == 1:
            return StateVector(out)
        return StateVectors(out)

    def jacobian(self, state: Any, **kwargs: Any) -> np.ndarray:
        """The Jacobian (L, ndim_state) of the delays at the state's position (E3), s/m; the
        state becomes the linearisation point of a link-budget R."""
        pos = self._positions(state)
        if pos.shape[0] != 1:
            raise _error("state", "the Jacobian is taken at one state")
        self._linearisation = pos[0]
        g = self.scenario.delay_jacobian(pos[0])[self._links]  # (L, 2)
        h = np.zeros((self.ndim_meas, self.ndim_state))
        h[:, self.mapping[0]] = g[:, 0]
        h[:, self.mapping[1]] = g[:, 1]
        return h

    def covar(self, state: Any = None, **kwargs: Any) -> CovarianceMatrix:
        """R = diag(sigma_p^2), s^2: the fixed ``sigma``'s, or the link budget's at ``state``
        (default: the latest linearisation state)."""
        if self.sigma is not None:
            return self.noise_covar
        if state is not None:
            pos = self._positions(state)[0]
        elif self._linearisation is not None:
            pos = self._linearisation
        else:
            raise _error(
                "state",
                "R from the link budget needs a state: call jacobian(state) (as the EKF "
                "updater does) or covar(state=...), or give a fixed sigma",
            )
        s = self.scenario.sigma_delays(pos)[self._links]
        return CovarianceMatrix(np.diag(s**2))

    def rvs(self, num_samples: int = 1, **kwargs: Any) -> Union[StateVector, StateVectors]:
        """Noise samples with covariance R."""
        covar = self.covar(**kwargs)
        noise = np.random.multivariate_normal(np.zeros(self.ndim_meas), covar, num_samples).T
        if num_samples == 1:
            return StateVector(noise)
        return StateVectors(noise)

    def pdf(self, state1: Any, state2: Any, **kwargs: Any) -> Any:
        """Likelihood of measurement ``state1`` given state ``state2``."""
        return np.exp(self.logpdf(state1, state2, **kwargs))

    def logpdf(self, state1: Any, state2: Any, **kwargs: Any) -> Any:
        """Log-likelihood of measurement ``state1`` given state ``state2`` (Gaussian with R
        at ``state2`` for a link-budget R)."""
        z = np.asarray(state1.state_vector, dtype=float)
        mean = np.asarray(self.function(state2, **kwargs), dtype=float)
        if self.sigma is not None:
            var = np.diag(np.asarray(self.noise_covar))[:, None]
        else:
            pos = self._positions(state2)
            var = (self.scenario.sigma_delays(pos)[:, self._links] ** 2).T
        r = (z - mean) ** 2 / var
        ll = -0.5 * (np.sum(r, axis=0) + np.sum(np.log(2 * np.pi * var), axis=0))
        if ll.size == 1:
            return float(ll[0])
        return ll
