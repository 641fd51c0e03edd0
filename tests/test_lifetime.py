"""A flown diagram is freed: its Python systems (with what they hold: plans, programs) do not
outlive the flight (systems/lifetime.py). Without it a re-planning campaign's worker grew by
about 0.2 GB a sample and never gave it back."""
import gc
import weakref

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder, LeafSystem, PublishEvent, WitnessFunctionDirection
from pydrake.systems.primitives import ConstantVectorSource

from drake_entry.campaign.sample import run_sample
from drake_entry.diagrams.closed_loop import ClosedLoopSetup
from drake_entry.scenario import load_scenario
from drake_entry.systems.actuators import BankActuator
from drake_entry.systems.lifetime import release_system, weak_element, weak_method


def live_python_systems() -> int:
    gc.collect()
    return sum(1 for o in gc.get_objects() if isinstance(o, LeafSystem) and not type(o).__module__.startswith("pydrake."))


class Doubler(LeafSystem):
    """Every kind of callback Drake holds: an output port, a periodic event, a witness and its event."""

    def __init__(self):
        super().__init__()
        self.u_port = self.DeclareVectorInputPort("u", 1)
        self._count = self.DeclareDiscreteState(1)
        self.DeclareVectorOutputPort("y", 1, weak_method(self._double))
        self.DeclareVectorOutputPort("count", 1, weak_element(self._counted, 0))
        self.DeclarePeriodicDiscreteUpdateEvent(0.1, 0.0, weak_method(self._tick))
        self.crossed_at = None
        self._witnesses = [self.MakeWitnessFunction(
            "half time", WitnessFunctionDirection.kPositiveThenNonPositive, weak_method(self._to_go, 0.55),
            PublishEvent(weak_method(self._crossed)))]
        self.payload = np.zeros(10_000)  # what a guidance system holds (a plan, a program)

    def _double(self, context, output):
        output.SetFromVector(2.0 * self.u_port.Eval(context))

    def _counted(self, context):
        return context.get_discrete_state(self._count).get_value()

    def _tick(self, context, discrete_state):
        discrete_state.get_mutable_vector(self._count).SetAtIndex(0, self._counted(context)[0] + 1.0)

    def _to_go(self, context, when):
        return when - context.get_time()

    def _crossed(self, context, event):
        self.crossed_at = context.get_time()

    def DoGetWitnessFunctions(self, context):
        return self._witnesses


def fly_doubler():
    """Builds, flies and releases a diagram with a Doubler; returns a weak reference to the
    Doubler and what it computed."""
    builder = DiagramBuilder()
    source = builder.AddSystem(ConstantVectorSource([1.5]))
    doubler = builder.AddSystem(Doubler())
    builder.Connect(source.get_output_port(), doubler.get_input_port())
    diagram = builder.Build()
    simulator = Simulator(diagram)
    simulator.get_mutable_context().SetAccuracy(1e-8)
    simulator.AdvanceTo(1.0)
    context = doubler.GetMyContextFromRoot(simulator.get_context())
    computed = (doubler.get_output_port(0).Eval(context)[0], doubler.get_output_port(1).Eval(context)[0],
                doubler.crossed_at)
    assert release_system(diagram) > 0
    return weakref.ref(doubler), computed


def test_the_callbacks_compute_through_their_weak_references_and_the_flown_diagram_is_freed():
    before = live_python_systems()
    doubler, (y, ticks, crossed_at) = fly_doubler()
    assert y == 3.0
    assert ticks == 10  # updates at 0, 0.1, ..., 0.9 (the one at 1.0 starts the next step)
    assert crossed_at == pytest.approx(0.55, abs=1e-6)  # the witness localised its zero
    assert doubler() is None
    assert live_python_systems() == before


def test_a_weak_callback_of_a_freed_system_says_so():
    class Owner:
        def value(self, x, scale):
            return x * scale

    owner = Owner()
    callback = weak_method(owner.value, 3.0)
    assert callback(2.0) == 6.0
    del owner
    gc.collect()
    with pytest.raises(RuntimeError, match="Owner.value called after its system was freed"):
        callback(2.0)


def test_a_system_never_added_to_a_diagram_is_freed_once_released():
    actuator = BankActuator(bank_limit=1.4, rate_limit=0.2, accel_limit=0.2, initial_bank=0.0, period=0.1)
    ref = weakref.ref(actuator)
    assert release_system(actuator) > 0  # the links to its ports
    del actuator
    gc.collect()
    assert ref() is None


def test_campaign_samples_leave_no_system_alive():
    """Two closed-loop samples of HORUS-2B (plant, navigation, drag-energy guidance, actuators,
    monitors) through the campaign's own run_sample: no Python system outlives its sample."""
    setup = ClosedLoopSetup.from_scenario(load_scenario("horus2b"))
    before = live_python_systems()
    rows = [run_sample(setup, 7, i, trajectory_step_s=0.0)[0] for i in range(2)]
    assert all(row["success"] for row in rows), [row["message"] for row in rows]
    assert live_python_systems() == before


@pytest.mark.parametrize("actuator_systems", [False, True])
def test_a_plan_verification_flight_leaves_no_system_alive(actuator_systems):
    """The verifier's flight of a plan through the closed loop's actuators (their response
    flown, or the actuator systems themselves): no Python system outlives it, the actuators
    built for the response included. A re-planning method flies one per plan."""
    from drake_entry.diagrams.verification import fly_controls
    from drake_entry.models.atmosphere import US76Atmosphere
    from drake_entry.models.planet import Earth
    from drake_entry.models.vehicles import load_vehicle
    from drake_entry.planning.verification import Actuation, EntryControls

    horus = load_vehicle("horus2b")
    actuation = Actuation(period_s=1.0, lead_s=0.0, bank_limit=1.4, bank_rate_limit=0.35, bank_accel_limit=0.35,
                          alpha_bounds=(0.0, 0.7), alpha_rate_limit=0.1, alpha_accel_limit=0.1, initial_bank=0.5,
                          initial_alpha=0.4)
    controls = EntryControls(horus, Earth.spherical(), US76Atmosphere(),
                             np.array([80e3, 0.1, 0.2, 7000.0, -0.01, 1.0]), 60.0, np.array([0.0, 60.0]),
                             np.array([0.5, 0.8]), np.array([0.4, 0.4]), actuation=actuation)
    before = live_python_systems()
    flown = fly_controls(controls, actuator_systems=actuator_systems)
    assert not flown.failure and flown.time[-1] == pytest.approx(60.0)
    assert flown.trajectory.bank[-1] == pytest.approx(0.8, abs=0.01)  # the actuator followed the plan's ramp
    assert live_python_systems() == before
