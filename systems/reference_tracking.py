"""ReferenceTracker: makes a reference at the entry interface from the navigation estimate and
tracks it with a time-varying LQR (paper 003's guidance for both AMPI and NTT; the
reference maker is ``guidance.ampi.reference.DatabaseReference``).

At initialisation the tracker asks ``planner.reference(estimate)`` for a TrackedReference
(the reference and its law u = u_ref - K (x - x_ref), planning.tracking). The law's state is
the reference problem's: the six entry states, the bank and a clock ([h, lon, lat, V, gamma,
psi, sigma, t], controls 'bank_rate'); the bank it feeds back is the tracker's own command,
which the shared bank actuator follows. Every ``period`` T the command follows the reference
bank and integrates only the feedback, sigma_c(t + T) = sigma_ref(t + T + L) + [sigma_c(t) -
sigma_ref(t + L)] - K (x - x_ref) T, with L the ``lead`` (integrating u_ref as well would drift
by up to |u| T per step), its change clipped to the rate limit times T and its value to the bank limit. A reference that
cannot be made (e.g. an enclosing database case not verified) is recorded: the tracker then
holds its initial bank and the flight is not a success.

The reference is read at the flight's clock t (``index`` 'time', paper 003's tracking) or at the
reference time where its energy E = V^2/2 - mu/r (central gravity) equals the estimate's
(``index`` 'energy'): a denser or draggier flight spends its energy sooner, and read in time its
reference would ask the altitude and speed of a later state it has not reached; read in energy
the law compares states of the same energy, and the clock's deviation is zero.

With ``model_scales`` the tracker also reads the lift and drag ratios the flight has sensed,
k_L and k_D (systems/acceleration_ratios.py), and flies the reference the flight's own air and
aerodynamics call for (``sensed_reference``): the state of the reference's energy where the
sensed drag equals the reference's (the altitude moved by about H ln k_D, H the density scale
height, less at low speed where the speed traded for that altitude changes the drag too), so
that the range flown per unit of energy, dR/dE = -cos(gamma) / (D/m), is the reference's; and
the feed-forward bank with cos(sigma_ff) = cos(sigma_ref) k_D / k_L, the reference's vertical
lift there. A plan made at the entry with the nominal models (paper 003's) otherwise asks a
denser or draggier flight for the nominal altitude, and the range it loses per unit of energy
is the drag's excess.

With ``path`` (a PathLimits, not paper 003's) each update's command also flies Lu 2014's
path-limit feedback (guidance/path_feedback.py, as FNPEG's and paper 004's laws do): where the
sensed load, heat rate or dynamic pressure would pass ``path``'s limits a horizon ahead,
cos(sigma_c) is raised by k V (max{sin gamma, U} - sin gamma) sqrt(g0/R0) / L, the sign kept. The
tracker carries the lifted command on (its offset from the feed-forward, as the feedback's), so
the lift stays until the TVLQR feedback returns the flight to its reference. The TVLQR itself
sees no limit: a flight away from its reference, or in denser air than planned, may pass one (the
capsule's final dive passed its q in 21 of 100 runs without the feedback).

Ports:
  - input  "estimated_state"  [6]  navigation estimate [h m, lon, lat rad, V m/s, gamma, psi rad]
  - input  "model_scales"     [2]  (model_scales only) k_L, k_D sensed
  - input  "flight_conditions" [9] (path only) sensed flight conditions (FLIGHT_CONDITION_NAMES)
  - output "bank_command"     [1]  sigma_c [rad]
  - output "reference_state"  [7]  the reference [h m, lon, lat rad, V m/s, gamma, psi, sigma rad] now
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import BasicVector, LeafSystem

from drake_entry.errors import DrakeEntryError, ScenarioError
from drake_entry.guidance.ampi.spec import TRACKING_INDICES
from drake_entry.guidance.path_feedback import PathLimits, corrected_cos_bank, path_limit_correction
from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES, specific_energy
from drake_entry.systems.lifetime import weak_method

__all__ = ["LAW_STATES", "SCALE_HEIGHT_STEP_M", "TrackerMemory", "ReferenceTracker", "sensed_reference",
           "sensed_bank", "limited_bank"]

_FC = {name: i for i, name in enumerate(FLIGHT_CONDITION_NAMES)}

#: the reference problem's state layout the law is written in
LAW_STATES = ("h", "lon", "lat", "V", "gamma", "psi", "sigma", "t")
#: the altitude step [m] of the density scale height's central difference
SCALE_HEIGHT_STEP_M = 100.0


def sensed_reference(h_ref: float, V_ref: float, sigmas, scales, density, gravity: float) -> tuple[float, float, list[float]]:
    """(the altitude [m], the speed [m/s], the bank angles [rad]) a flight whose sensed lift and
    drag are ``scales`` = (k_L, k_D) times the nominal models' flies for a reference at altitude
    ``h_ref`` [m] and speed ``V_ref`` [m/s] with bank angles ``sigmas`` [rad]: the state of the
    reference's energy (V^2/2 + g h, ``gravity`` g [m/s^2]) where the sensed drag is the
    reference's, k_D rho(h) V^2 = rho(h_ref) V_ref^2, to first order in ln k_D: h = h_ref + dh,
    dh = ln k_D / (1/H + 2 g / V_ref^2) with the local scale height H of ``density`` (altitude
    [m] -> kg/m^3), V^2 = V_ref^2 - 2 g dh; each bank with cos(sigma) = cos(sigma_ref) k_D / k_L
    (the reference's vertical lift; clipped to [-1, 1]), its sign kept."""
    k_d = float(scales[1])
    step = SCALE_HEIGHT_STEP_M
    H = 2.0 * step / math.log(density(h_ref - step) / density(h_ref + step))
    dh = math.log(k_d) / (1.0 / H + 2.0 * gravity / (V_ref * V_ref))
    V = math.sqrt(max(V_ref * V_ref - 2.0 * gravity * dh, 0.0))
    return h_ref + dh, V, [sensed_bank(s, scales) for s in sigmas]


def sensed_bank(sigma_ref: float, scales) -> float:
    """The bank [rad] with cos(sigma) = cos(``sigma_ref``) k_D / k_L (clipped to [-1, 1]), the
    sign of ``sigma_ref``: the reference's vertical lift where the sensed drag is the reference's
    (``sensed_reference``), ``scales`` = (k_L, k_D)."""
    ratio = float(scales[1]) / float(scales[0])
    return math.copysign(math.acos(min(max(math.cos(sigma_ref) * ratio, -1.0), 1.0)), sigma_ref)


def limited_bank(sigma: float, x, conditions, path: PathLimits, bank_limit: float) -> float:
    """The bank [rad] ``sigma`` with Lu 2014's path-limit feedback (module docstring) at the
    estimate ``x`` [h, lon, lat, V, gamma, psi] and the sensed ``conditions`` (FLIGHT_CONDITION_NAMES):
    |sigma| only lowered, within ``bank_limit`` [rad], its sign kept; unchanged without lift."""
    L, D = float(conditions[_FC["lift"]]), float(conditions[_FC["drag"]])
    if not L > 0.0:
        return sigma
    term = path_limit_correction(float(x[3]), math.sin(float(x[4])), D, math.hypot(L, D),
                                 float(conditions[_FC["heat_flux"]]), float(conditions[_FC["dynamic_pressure"]]), path)
    c = corrected_cos_bank(math.cos(sigma), term, L, path.R0, path.g0)
    return math.copysign(math.acos(min(max(c, math.cos(bank_limit)), 1.0)), sigma)


@dc.dataclass(frozen=True)
class TrackerMemory:
    """reference: the TrackedReference (None when it could not be made); message: why not;
    energy: the reference's energy at its samples [J/kg], non-increasing (index 'energy' only)."""

    reference: object = None
    message: str = ""
    energy: np.ndarray | None = None


class ReferenceTracker(LeafSystem):
    def __init__(self, planner, *, bank_limit: float, rate_limit: float, period: float = 0.5,
                 initial_bank: float = 0.0, lead: float = 0.0, index: str = "time", density=None,
                 path: PathLimits | None = None):
        """Args: planner with reference(estimate) -> TrackedReference and ``problem.state_names``
        == LAW_STATES; bank_limit [rad], rate_limit [rad/s] of the command; period [s];
        initial_bank [rad] (held when no reference can be made); lead [s]: the feed-forward is
        the reference bank this far ahead, the lag of the actuator loop the command drives;
        index: 'time' or 'energy', what the reference is read at (module docstring); density:
        the nominal atmosphere's density [kg/m^3] at an altitude [m], given to read the
        reference at the sensed lift and drag ratios (input "model_scales", module docstring);
        path: Lu 2014's path-limit feedback on the command (input "flight_conditions", module
        docstring; None or inactive: none)."""
        super().__init__()
        if tuple(planner.problem.state_names) != LAW_STATES:
            raise ScenarioError(f"ReferenceTracker needs a reference with states {LAW_STATES} (controls 'bank_rate'), "
                                f"got {tuple(planner.problem.state_names)}")
        for name, v in (("bank_limit", bank_limit), ("rate_limit", rate_limit), ("period", period)):
            if not v > 0:
                raise ScenarioError(f"ReferenceTracker.{name} = {v}: must be > 0")
        if not 0.0 <= lead <= 10.0:
            raise ScenarioError(f"ReferenceTracker.lead = {lead} s: allowed 0 to 10")
        self.planner, self.bank_limit, self.rate_limit, self.period = planner, bank_limit, rate_limit, period
        if index not in TRACKING_INDICES:
            raise ScenarioError(f"ReferenceTracker.index = '{index}'; allowed: {', '.join(TRACKING_INDICES)}")
        self.lead, self.index = float(lead), index
        self._planet = planner.problem.planet.with_(j2=0.0)  # central gravity: the closed loop's stop
        self.est_port = self.DeclareVectorInputPort("estimated_state", 6)
        self.density = density
        self.scales_port = None if density is None else self.DeclareVectorInputPort("model_scales", 2)
        if density is not None:  # the ratios of the last update (its feed-forward's)
            self._scales = self.DeclareDiscreteState(BasicVector([1.0, 1.0]))
        self.path = path if path is not None and path.active else None
        self.fc_port = None if self.path is None else self.DeclareVectorInputPort(
            "flight_conditions", len(FLIGHT_CONDITION_NAMES))
        self._memory = self.DeclareAbstractState(AbstractValue.Make(TrackerMemory()))
        self._bank = self.DeclareDiscreteState(BasicVector([float(initial_bank)]))
        self.DeclareInitializationUnrestrictedUpdateEvent(weak_method(self._start))
        self.DeclarePeriodicDiscreteUpdateEvent(period, 0.0, weak_method(self._update))
        self.DeclareStateOutputPort("bank_command", self._bank)
        self.DeclareVectorOutputPort("reference_state", 7, weak_method(self._reference_state),
                                     prerequisites_of_calc={self.all_state_ticket(), self.time_ticket(),
                                                            self.all_input_ports_ticket()})

    def memory(self, context) -> TrackerMemory:
        return context.get_abstract_state(int(self._memory)).get_value()

    def _start(self, context, state):
        estimate = np.asarray(self.est_port.Eval(context), float)
        try:
            ref = self.planner.reference(estimate)
        except DrakeEntryError as e:  # recorded; the flight goes on without guidance
            state.get_mutable_abstract_state(int(self._memory)).set_value(TrackerMemory(None, str(e)))
            return
        energy = None
        if self.index == "energy":  # non-increasing, so that every energy reads one time
            energy = np.minimum.accumulate(specific_energy(ref.law.states.T, self._planet))
        memory = TrackerMemory(ref, energy=energy)
        state.get_mutable_abstract_state(int(self._memory)).set_value(memory)
        s = self._clock(context, memory)
        sigma0 = float(np.clip(ref.law.state(s + self.lead)[6], -self.bank_limit, self.bank_limit))
        state.get_mutable_discrete_state(self._bank).SetFromVector([sigma0])

    def _clock(self, context, memory: TrackerMemory) -> float:
        """The reference time [s] the law is read at now."""
        if memory.energy is None:
            return context.get_time()
        x = self.est_port.Eval(context)
        law = memory.reference.law
        # np.interp needs increasing abscissae: the energy falls along the reference
        return float(np.interp(-specific_energy(x, self._planet), -memory.energy, law.time))

    def _update(self, context, discrete_state):
        memory = self.memory(context)
        ref = memory.reference
        if ref is None:
            return
        t, T, lead = self._clock(context, memory), self.period, self.lead
        sigma = float(context.get_discrete_state(self._bank).GetAtIndex(0))
        law = ref.law
        ff_now, ff_next = law.state(t + lead)[6], law.state(t + T + lead)[6]
        x_ref = law.state(t)
        if self.scales_port is not None:  # the offset carried is the command's from the last feed-forward
            scales = np.asarray(self.scales_port.Eval(context), float)
            before = context.get_discrete_state(self._scales).get_value()
            x_ref, g = x_ref.copy(), self._planet.mu / self._planet.radius(x_ref[0]) ** 2
            x_ref[0], x_ref[3], (ff_next, x_ref[6]) = sensed_reference(x_ref[0], x_ref[3], (ff_next, x_ref[6]), scales,
                                                                       self.density, g)
            ff_now = sensed_bank(ff_now, before)
            discrete_state.get_mutable_vector(self._scales).SetFromVector(scales)
        # the bank deviation is the command's from the feed-forward (the reference bank
        # ``lead`` seconds ahead, which the lagging actuator delivers now)
        x = np.concatenate([self.est_port.Eval(context), [x_ref[6] + sigma - ff_now, t]])
        feedback = float(law.gain(t)[0] @ (x - x_ref))
        target = ff_next + (sigma - ff_now) - feedback * T
        step = min(max(target - sigma, -self.rate_limit * T), self.rate_limit * T)
        command = min(max(sigma + step, -self.bank_limit), self.bank_limit)
        if self.path is not None:
            command = limited_bank(command, x, self.fc_port.Eval(context), self.path, self.bank_limit)
        discrete_state.get_mutable_vector(self._bank).SetFromVector([command])

    def _reference_state(self, context, output):
        memory = self.memory(context)
        ref = memory.reference
        output.SetFromVector(np.full(7, np.nan) if ref is None else ref.law.state(self._clock(context, memory))[:7])
