"""Stone Soup measurement models of bistatic delays and range rates (needs ``pip install
scatterloc[stonesoup]``).

:class:`BistaticDelayModel` is a Stone Soup ``NonLinearGaussianMeasurement`` whose
``function`` (the delays, spec E1), ``jacobian`` (their gradient, E3) and ``covar`` (R: a fixed
delay sigma, or the link budget's, E8) come from the scatterloc core, so Stone Soup's own
``ExtendedKalmanUpdater``, ``UnscentedKalmanUpdater``, particle updaters, trackers, data
associators and metrics run on scatterloc's geometry. Stone Soup itself has monostatic
range/bearing models only.

:class:`BistaticDelayDopplerModel` adds the links' range rates (docs/doppler.md, D1-D6): the
measurement is the delays followed by the range rates, so one update also measures the
velocity.

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

from ._scatterloc import Scenario, ScatterlocError, range_rates, sigma_range_rates

__all__ = ["BistaticDelayDopplerModel", "BistaticDelayModel"]


def _error(field: str, message: str) -> ScatterlocError:
    """A ScatterlocError naming ``field``, as the native functions raise them."""
    e = ScatterlocError(f"{field}: {message}")
    e.field = field
    e.kind = "InvalidArgument"
    return e


class _ScatterlocMeasurement(NonLinearGaussianMeasurement):  # type: ignore[misc]
    """What both models share: keyword arguments only, a ``scenario`` (a
    :class:`scatterloc.Scenario`, or what its constructor takes), R built from the sigmas
    (never a given ``noise_covar``), and noise samples and likelihoods from ``covar`` and
    ``logpdf``."""

    @staticmethod
    def _checked_arguments(
        name: str, usage: str, covar_error: str, args: tuple[Any, ...], kwargs: dict[str, Any]
    ) -> None:
        """Checks model ``name``'s constructor arguments before Stone Soup's ``__init__``
        (``usage``: the keywords named when positional ones are given; ``covar_error``: the
        error for a given ``noise_covar``, which R is built from) and sets a placeholder
        ``noise_covar`` in ``kwargs`` until the real R is known (the parent converts it)."""
        if args:
            raise TypeError(f"{name} takes keyword arguments ({usage})")
        scenario = kwargs.get("scenario")
        if scenario is None:
            raise _error("scenario", "required")
        if not isinstance(scenario, Scenario):
            kwargs["scenario"] = Scenario(scenario)
        if kwargs.get("noise_covar") is not None:
            raise _error("noise_covar", covar_error)
        kwargs["noise_covar"] = np.eye(1)

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


class BistaticDelayModel(_ScatterlocMeasurement):
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
        self._checked_arguments(
            "BistaticDelayModel",
            "scenario=..., sigma=..., links=...",
            "set sigma instead (R is built from it)",
            args,
            kwargs,
        )
        super().__init__(*args, **kwargs)
        self._links = _link_list(self.links, self.scenario.link_count, "links", at_least_one=True)
        if len(self.mapping) != 2:
            raise _error("mapping", "expected the two position components (x, y)")
        self._linearisation: Optional[np.ndarray] = None
        if self.sigma is None:
            self.noise_covar = None
        else:
            s = _fixed_sigmas(self.sigma, self._links.size, "sigma", "s", what="delay sigma")
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


def _link_list(
    links: Optional[Sequence[int]], n: int, field: str, at_least_one: bool = False
) -> np.ndarray:
    """``links`` (default: all ``n``) as checked distinct indices into the scenario's links
    (with ``at_least_one``, not none)."""
    out = list(range(n)) if links is None else [int(p) for p in links]
    for p in out:
        if not 0 <= p < n:
            raise _error(field, f"link {p} is not in 0..{n - 1}")
    if len(set(out)) != len(out) or (at_least_one and not out):
        need = ", at least one" if at_least_one else ""
        raise _error(field, f"expected distinct link indices{need}")
    return np.asarray(out, dtype=np.intp)


def _fixed_sigmas(sigma: Any, n: int, field: str, unit: str, what: str = "sigma") -> np.ndarray:
    """A fixed sigma (one for every link or one per link of ``n``), each finite and > 0
    (``what``: the sigma's name in the errors)."""
    s = np.asarray(sigma, dtype=float)
    if s.ndim > 1 or (s.ndim == 1 and s.size != n):
        raise _error(
            field, f"expected one {what} or {n} (one per measured link), got shape {s.shape}"
        )
    s = np.broadcast_to(s, (n,))
    if not np.all(np.isfinite(s) & (s > 0)):
        raise _error(field, f"every {what} must be a finite number > 0 {unit}")
    return np.array(s, dtype=float)


class BistaticDelayDopplerModel(_ScatterlocMeasurement):
    r"""Bistatic delays and range rates of a moving scatterer on a scatterloc scenario's links
    (issue 42, docs/doppler.md).

    For a state with position :math:`r` (the components ``mapping`` picks) and velocity
    :math:`v` (``velocity_mapping``), the measurement is the delays :math:`\tau_p(r)` (s, spec
    E1) of the links ``delay_links`` followed by the range rates
    :math:`\dot r_p = (\hat u_T + \hat u_R)\cdot v` (m/s, D1) of the links ``rate_links``
    (each default: every link, in the scenario's link order; either may be empty, not both).

    The Jacobian comes from the core: a delay row is :math:`[\nabla\tau_p, 0]` (E3), a rate
    row :math:`[\partial\dot r_p/\partial r, \partial\dot r_p/\partial v]` (D3), placed in
    the ``mapping`` and ``velocity_mapping`` columns.

    :math:`R = \mathrm{diag}(\sigma_{\tau,p}^2, \sigma_{\dot r,p}^2)` (D6) over one CPI of
    ``cpi`` snapshots ``cpi_spacing_s`` apart:

    - ``sigma`` (s): fixed, one for all delay links or one per delay link; None: the link
      budget's :math:`\sigma_{\tau,p}(r)/\sqrt{N}` (E8 over the CPI's N snapshots; ``cpi=1``
      gives one snapshot's);
    - ``sigma_range_rate`` (m/s): fixed, one or one per rate link; None: the CPI's
      :math:`\sqrt{\lambda^2/F_{ff} + \sigma_{floor}^2}` (D4-D5, :func:`scatterloc.sigma_range_rates`,
      floor ``range_rate_floor``) at the link's SNR; needs ``cpi`` >= 2.

    A state-dependent R is taken at the linearisation state (the latest ``jacobian`` call: the
    predicted state in Stone Soup's ``ExtendedKalmanUpdater``) or at ``covar(state=...)``, as
    :class:`BistaticDelayModel`'s. Its Fisher information :math:`H^T R^{-1} H` with both
    defaults is :func:`scatterloc.crlb_doppler`'s ``fim`` (D7), in the state's order.
    """

    scenario: Scenario = Property(doc="The scatterloc scenario (nodes, links, link budget).")
    sigma: Optional[Union[float, Sequence[float]]] = Property(
        default=None,
        doc="Delay standard deviation, s: one for every delay link or one per delay link. "
        "None: the link budget's (E8) over the CPI's snapshots, at the linearisation state.",
    )
    sigma_range_rate: Optional[Union[float, Sequence[float]]] = Property(
        default=None,
        doc="Range-rate standard deviation, m/s: one for every rate link or one per rate "
        "link. None: the CPI's (D5) at the linearisation state.",
    )
    delay_links: Optional[Sequence[int]] = Property(
        default=None,
        doc="Scenario links whose delays are measured, in measurement order (default: all).",
    )
    rate_links: Optional[Sequence[int]] = Property(
        default=None,
        doc="Scenario links whose range rates are measured, after the delays (default: all).",
    )
    cpi: int = Property(default=16, doc="Snapshots N in the CPI (D4-D6).")
    cpi_spacing_s: float = Property(default=2.048e-3, doc="The snapshots' spacing T, s.")
    range_rate_floor: float = Property(
        default=0.1, doc="The floor on the range rate's sigma, m/s (D5)."
    )
    ndim_state: int = Property(default=4, doc="Number of state dimensions.")
    mapping: Sequence[int] = Property(
        default=(0, 2), doc="The state components that are the position (x, y)."
    )
    velocity_mapping: Sequence[int] = Property(
        default=(1, 3), doc="The state components that are the velocity (vx, vy)."
    )
    noise_covar: CovarianceMatrix = Property(
        default=None, doc="Set from the sigmas; do not give it."
    )

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self._checked_arguments(
            "BistaticDelayDopplerModel",
            "scenario=..., sigma=..., sigma_range_rate=..., ...",
            "set sigma and sigma_range_rate instead (R is built from them)",
            args,
            kwargs,
        )
        super().__init__(*args, **kwargs)
        n = self.scenario.link_count
        self._delay_links = _link_list(self.delay_links, n, "delay_links")
        self._rate_links = _link_list(self.rate_links, n, "rate_links")
        if self._delay_links.size + self._rate_links.size == 0:
            raise _error("rate_links", "no link measured: give delay_links or rate_links")
        for field in ("mapping", "velocity_mapping"):
            if len(getattr(self, field)) != 2:
                raise _error(field, "expected two state components (x, y)")
        cols = [int(c) for c in (*self.mapping, *self.velocity_mapping)]
        if len(set(cols)) != 4 or not all(0 <= c < self.ndim_state for c in cols):
            raise _error(
                "velocity_mapping",
                f"mapping and velocity_mapping must be four distinct state components in "
                f"0..{self.ndim_state - 1}, got {tuple(self.mapping)} and "
                f"{tuple(self.velocity_mapping)}",
            )
        if isinstance(self.cpi, bool) or not isinstance(self.cpi, (int, np.integer)):
            raise _error("cpi.snapshots", f"expected a whole number of snapshots, got {self.cpi!r}")
        # The core checks the CPI (named errors: cpi.snapshots, cpi.spacing_s, cpi.floor_mps).
        x0, x1, y0, y1 = self.scenario.area
        probe = sigma_range_rates(self.scenario, ((x0 + x1) / 2, (y0 + y1) / 2), **self._cpi_kw())
        if self.sigma_range_rate is None and self._rate_links.size and not np.isfinite(probe).all():
            raise _error(
                "cpi.snapshots",
                f"a CPI of {self.cpi} snapshot(s) measures no range rate: give "
                "sigma_range_rate, or cpi >= 2",
            )
        self._sigma = (
            None if self.sigma is None
            else _fixed_sigmas(self.sigma, self._delay_links.size, "sigma", "s")
        )
        self._sigma_rate = (
            None if self.sigma_range_rate is None
            else _fixed_sigmas(
                self.sigma_range_rate, self._rate_links.size, "sigma_range_rate", "m/s"
            )
        )
        self._linearisation: Optional[np.ndarray] = None
        if self._sigma is not None and self._sigma_rate is not None:
            self.noise_covar = CovarianceMatrix(
                np.diag(np.concatenate([self._sigma, self._sigma_rate]) ** 2)
            )
        else:
            self.noise_covar = None

    def _cpi_kw(self) -> dict[str, Any]:
        return {
            "cpi": int(self.cpi),
            "cpi_spacing_s": float(self.cpi_spacing_s),
            "range_rate_floor": float(self.range_rate_floor),
        }

    @property
    def ndim_meas(self) -> int:
        """Number of measured values: delay links, then rate links."""
        return int(self._delay_links.size + self._rate_links.size)

    def _states(self, state: Any) -> np.ndarray:
        """The states (N, 4) ``[x, y, vx, vy]`` of a state, its state vector or its state
        vectors."""
        sv = state.state_vector if hasattr(state, "state_vector") else state
        sv = np.asarray(sv, dtype=float)
        if sv.ndim == 1:
            sv = sv[:, None]
        cols = [*self.mapping, *self.velocity_mapping]
        return np.ascontiguousarray(np.stack([sv[c, :] for c in cols], axis=1))

    def _sigmas(self, xs: np.ndarray) -> np.ndarray:
        """The measurement sigmas (M, N) at the states ``xs`` (N, 4)."""
        n = xs.shape[0]
        pos = np.ascontiguousarray(xs[:, :2])
        if self._sigma is not None:
            sd = np.broadcast_to(self._sigma[:, None], (self._delay_links.size, n))
        else:
            sd = (self.scenario.sigma_delays(pos)[:, self._delay_links] / np.sqrt(self.cpi)).T
        if self._sigma_rate is not None:
            sr = np.broadcast_to(self._sigma_rate[:, None], (self._rate_links.size, n))
        else:
            sr = sigma_range_rates(self.scenario, pos, **self._cpi_kw())[:, self._rate_links].T
        return np.concatenate([sd, sr], axis=0)

    def function(self, state: Any, noise: Any = False, **kwargs: Any) -> Union[StateVector, StateVectors]:
        """The delays (s, E1) of the delay links, then the range rates (m/s, D1) of the rate
        links, at the state's position and velocity."""
        xs = self._states(state)
        delays = self.scenario.delays(np.ascontiguousarray(xs[:, :2]))[:, self._delay_links].T
        rates = range_rates(self.scenario, xs)[0][:, self._rate_links].T
        out = np.concatenate([delays, rates], axis=0)  # (M, N)
        if isinstance(noise, bool) or noise is None:
            if noise:
                noise = self._sigmas(xs) * np.random.standard_normal(out.shape)
            else:
                noise = 0
        out = out + noise
        if out.shape[1] == 1:
            return StateVector(out)
        return StateVectors(out)

    def jacobian(self, state: Any, **kwargs: Any) -> np.ndarray:
        """The Jacobian (M, ndim_state) at the state: delay rows ``[grad tau, 0]`` (E3, s/m),
        rate rows ``[d rdot/d r, d rdot/d v]`` (D3, 1/s and 1), in the ``mapping`` and
        ``velocity_mapping`` columns; the state becomes the linearisation point of a
        state-dependent R."""
        xs = self._states(state)
        if xs.shape[0] != 1:
            raise _error("state", "the Jacobian is taken at one state")
        self._linearisation = xs[0]
        g = self.scenario.delay_jacobian(xs[0, :2])[self._delay_links]  # (Ld, 2)
        jr = range_rates(self.scenario, xs[0])[1][self._rate_links]  # (Lr, 4)
        rows = np.zeros((self.ndim_meas, 4))
        rows[: g.shape[0], :2] = g
        rows[g.shape[0] :, :] = jr
        h = np.zeros((self.ndim_meas, self.ndim_state))
        for k, c in enumerate((*self.mapping, *self.velocity_mapping)):
            h[:, c] = rows[:, k]
        return h

    def covar(self, state: Any = None, **kwargs: Any) -> CovarianceMatrix:
        """R = diag(sigma_tau^2, sigma_rdot^2): the fixed sigmas, or the link budget's and the
        CPI's at ``state`` (default: the latest linearisation state)."""
        if self.noise_covar is not None:
            return self.noise_covar
        if state is not None:
            x = self._states(state)[0]
        elif self._linearisation is not None:
            x = self._linearisation
        else:
            raise _error(
                "state",
                "R from the link budget or the CPI needs a state: call jacobian(state) (as the "
                "EKF updater does) or covar(state=...), or give fixed sigmas",
            )
        s = self._sigmas(x[None, :])[:, 0]
        return CovarianceMatrix(np.diag(s**2))

    def logpdf(self, state1: Any, state2: Any, **kwargs: Any) -> Any:
        """Log-likelihood of measurement ``state1`` given state ``state2`` (Gaussian with R at
        ``state2`` where R depends on the state)."""
        z = np.asarray(state1.state_vector, dtype=float)
        mean = np.asarray(self.function(state2, **kwargs), dtype=float)
        var = self._sigmas(self._states(state2)) ** 2
        r = (z - mean) ** 2 / var
        ll = -0.5 * (np.sum(r, axis=0) + np.sum(np.log(2 * np.pi * var), axis=0))
        if ll.size == 1:
            return float(ll[0])
        return ll
