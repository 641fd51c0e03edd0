"""Scenario spec of paper 004's guidance; YAML tag ``guidance: !SwarmBank``."""

import dataclasses as dc
import typing

from drake_entry.errors import ScenarioError, check_range
from drake_entry.guidance.spec import ReplansOnBoard, ReversingBankSpec, check_alpha_in_speed

__all__ = ["ALPHA_LAWS", "SWARMS", "OPTIMIZERS", "swarm_trajectories", "MAX_SEARCH_TRAJECTORIES", "SwarmBank"]

#: the alpha laws: Case 1 (eq. 31), Case 2 (eq. 21, then eq. 31), and a given alpha in speed
ALPHA_LAWS = ("load", "heat", "schedule")
#: sigma_0 searches: the paper's swarms and the scipy baselines (guidance/swarm_bank/search.py)
#: the swarm optimizers (paper 004's PIO and PSO; their budget: swarm_trajectories)
SWARMS = ("pio", "pso", "pso_stable")
OPTIMIZERS = SWARMS + ("grid", "brentq", "secant", "bounded", "differential_evolution")


def swarm_trajectories(n: int, k_max: int) -> int:
    """Trajectories a swarm search integrates: its start and ``k_max`` iterations of ``n``."""
    return int(n) * (int(k_max) + 1)


#: the largest swarm search accepted [trajectories]: 10^5 take about 0.5-9 h on one core
#: (20 ms each in populations of 100, 340 ms in populations of 10)
MAX_SEARCH_TRAJECTORIES = 100_000


@dc.dataclass
class SwarmBank(ReversingBankSpec, ReplansOnBoard):
    """|sigma| linear in e = mu/r - V^2/2 from bank_start_deg at entry to bank_end_deg at the
    TAEM energy (paper 004 eq. 17) with the QEG compensation (eqs. 46-48); alpha from the load
    factor (Case 1, eq. 31), the heat rate until Mach_shift (Case 2, eq. 21) or a given schedule
    in speed ('schedule', for another method's mission); bank sign from
    the shared reversal logic. bank_start_deg is searched before flight (``optimizer``) unless
    given, and re-solved on board every ``replan_period_s`` when > 0."""

    # the TAEM interface of eq. 32 (r*, V*); the flight stops at its energy
    terminal_altitude_km: float = 30.0
    terminal_velocity_m_s: float = 2000.0
    # eq. 17: sigma_0 (None = search it in bank_start_bounds_deg) and sigma_f [deg]
    bank_start_deg: typing.Optional[float] = None
    bank_start_bounds_deg: list[float] = dc.field(default_factory=lambda: [0.0, 89.0])
    bank_end_deg: float = 60.0
    # sigma_f searched before flight with sigma_0 in these bounds [deg] (None: bank_end_deg, fixed;
    # paper 004's two-parameter search), then held while sigma_0 is re-solved on board
    bank_end_bounds_deg: typing.Optional[list[float]] = None
    # on board, where a re-solution's sigma_0 brackets no root of the range error (at its bound:
    # late in the flight eq. 17's weight on sigma_0 has shrunk), sigma_f is re-solved within
    # bank_end_bounds_deg with that sigma_0 held (not the paper's; needs bank_end_bounds_deg)
    resolve_bank_end: bool = False
    # alpha law: 'load' (Case 1, eq. 31), 'heat' (Case 2: eq. 21 until Mach < mach_shift) or
    # 'schedule' (alpha_deg at alpha_velocity_m_s, linear in speed: another method's alpha profile)
    alpha_law: str = "load"
    mach_shift: float = 20.0
    alpha_deg: list[float] = dc.field(default_factory=list)
    alpha_velocity_m_s: list[float] = dc.field(default_factory=list)
    # alpha bounds and actuator limits (paper 004: [10, 20] deg, 4 deg/s, 8 deg/s^2)
    alpha_min_deg: float = 10.0
    alpha_max_deg: float = 20.0
    alpha_rate_deg_s: float = 4.0
    alpha_accel_deg_s2: float = 8.0
    # eq. 32's units: J = |range error| / range + |altitude error| / altitude + |speed error| / speed
    # (paper 004: 100 nmi, 1 km, 100 m/s)
    objective_range_unit_km: float = 185.2
    objective_altitude_unit_km: float = 1.0
    objective_speed_unit_m_s: float = 100.0
    # under the 'schedule' alpha law (which holds no path limit) J is penalised for peaks past this
    # fraction of the vehicle's limits: the margin for what the replica's guidance steps miss
    limit_fraction: float = 1.0
    # QEG compensation (eq. 48 gain k2, eq. 46 nondimensional scale height beta)
    qeg_gain: float = 10.0
    qeg_beta: float = 920.0
    # Lu 2014's path-limit feedback on the bank under alpha_law 'schedule' (paper 004's alpha laws
    # hold the limits themselves; with them it is off): gain (0 = off; Lu: 40), prediction horizon
    # [s] and the fraction of the vehicle's limits held (guidance/path_feedback.py); flown on board
    # and in every prediction alike
    path_gain: float = 0.0
    path_horizon_s: float = 16.0
    path_limit_fraction: float = 0.9
    # sigma_0 search: pio | pso | pso_stable | grid | brentq | secant | bounded | differential_evolution
    optimizer: str = "pio"
    # swarm settings (paper 004: N 10, k_max 20, k_c 14, R 0.2)
    population: int = 10
    iterations: int = 20
    landmark_iteration: int = 14
    map_compass_factor: float = 0.2
    seed: int = 0
    # no re-solution past this normalised energy (little range is left to correct)
    replan_until_e: float = 0.95
    # the predictions fly the nominal lift and drag scaled by the filtered sensed/modelled
    # ratios (what the flight has shown of a density or aerodynamic error)
    acceleration_scaling: bool = True

    def terminal_speed(self, speed_of_sound: float) -> float:
        return self.terminal_velocity_m_s

    def validate(self, scenario) -> None:
        super().validate(scenario)
        check_range("guidance.terminal_velocity_m_s", self.terminal_velocity_m_s, 1.0, scenario.entry.velocity_m_s)
        bank_limit = scenario.make_vehicle().bank_limit_deg
        if len(self.bank_start_bounds_deg) != 2 or not self.bank_start_bounds_deg[0] < self.bank_start_bounds_deg[1]:
            raise ScenarioError(f"guidance.bank_start_bounds_deg = {self.bank_start_bounds_deg} needs [lower, upper] "
                                "with lower < upper")
        for v in self.bank_start_bounds_deg:  # eq. 17's sigma_0 may exceed the bank limit; |sigma| is clipped
            check_range("guidance.bank_start_bounds_deg", v, 0.0, 90.0)
        if self.bank_start_deg is not None:
            check_range("guidance.bank_start_deg", self.bank_start_deg, 0.0, 90.0)
        check_range("guidance.bank_end_deg", self.bank_end_deg, 0.0, bank_limit)
        if self.resolve_bank_end and self.bank_end_bounds_deg is None:
            raise ScenarioError("guidance.resolve_bank_end re-solves sigma_f within bank_end_bounds_deg: give "
                                "bank_end_bounds_deg [lower, upper] (deg), or set resolve_bank_end false")
        if self.bank_end_bounds_deg is not None:
            if len(self.bank_end_bounds_deg) != 2 or not self.bank_end_bounds_deg[0] < self.bank_end_bounds_deg[1]:
                raise ScenarioError(f"guidance.bank_end_bounds_deg = {self.bank_end_bounds_deg} needs [lower, upper] "
                                    "with lower < upper")
            for v in self.bank_end_bounds_deg:
                check_range("guidance.bank_end_bounds_deg", v, 0.0, bank_limit)
            if self.optimizer not in SWARMS + ("differential_evolution",):
                raise ScenarioError(f"guidance.bank_end_bounds_deg searches sigma_f with sigma_0, which "
                                    f"guidance.optimizer = {self.optimizer!r} cannot; allowed: "
                                    f"{', '.join(SWARMS)}, differential_evolution")
        if self.alpha_law not in ALPHA_LAWS:
            raise ScenarioError(f"guidance.alpha_law = {self.alpha_law!r}; allowed: 'load' (Case 1), 'heat' (Case 2), "
                                "'schedule' (alpha_deg at alpha_velocity_m_s)")
        check_range("guidance.mach_shift", self.mach_shift, 0.5, 40.0)
        check_range("guidance.alpha_min_deg", self.alpha_min_deg, -10.0, 60.0)
        check_range("guidance.alpha_max_deg", self.alpha_max_deg, self.alpha_min_deg + 1e-6, 60.0)
        if self.alpha_law == "schedule":  # the alpha actuator's position bounds hold the schedule
            check_alpha_in_speed(self.alpha_deg, self.alpha_velocity_m_s, self.alpha_min_deg, self.alpha_max_deg)
        check_range("guidance.alpha_rate_deg_s", self.alpha_rate_deg_s, 1e-3, 100.0)
        check_range("guidance.alpha_accel_deg_s2", self.alpha_accel_deg_s2, 1e-3, 1000.0)
        check_range("guidance.objective_range_unit_km", self.objective_range_unit_km, 1e-3, 1e5)
        check_range("guidance.objective_altitude_unit_km", self.objective_altitude_unit_km, 1e-3, 1e3)
        check_range("guidance.objective_speed_unit_m_s", self.objective_speed_unit_m_s, 1e-3, 1e5)
        check_range("guidance.limit_fraction", self.limit_fraction, 0.5, 1.0)
        check_range("guidance.qeg_gain", self.qeg_gain, 0.0, 1e4)
        check_range("guidance.qeg_beta", self.qeg_beta, 1.0, 1e5)
        check_range("guidance.path_gain", self.path_gain, 0.0, 1000.0)
        check_range("guidance.path_horizon_s", self.path_horizon_s, 0.1, 600.0)
        check_range("guidance.path_limit_fraction", self.path_limit_fraction, 0.5, 1.0)
        if self.optimizer not in OPTIMIZERS:
            raise ScenarioError(f"guidance.optimizer = {self.optimizer!r}; allowed: {', '.join(OPTIMIZERS)}")
        check_range("guidance.population", self.population, 2, 10000)
        check_range("guidance.iterations", self.iterations, 1, 10000)
        check_range("guidance.landmark_iteration", self.landmark_iteration, 1, self.iterations)
        trajectories = swarm_trajectories(self.population, self.iterations)
        if self.optimizer in SWARMS and trajectories > MAX_SEARCH_TRAJECTORIES:
            raise ScenarioError(
                f"guidance.population x (guidance.iterations + 1) = {trajectories:,} trajectories to integrate "
                f"before flight (20-340 ms each: {trajectories * 0.02 / 3600:,.0f} h or more); allowed up to "
                f"{MAX_SEARCH_TRAJECTORIES:,} (paper 004: 10 x 21 = 210)")
        check_range("guidance.seed", self.seed, 0, 2**32 - 1)
        check_range("guidance.map_compass_factor", self.map_compass_factor, 0.0, 10.0)
        check_range("guidance.replan_until_e", self.replan_until_e, 0.0, 1.0)
