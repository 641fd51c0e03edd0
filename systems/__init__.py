"""Drake LeafSystems of the entry plant, sensors, actuators and monitors."""

__all__ = ["acceleration_ratios", "actuators", "atmosphere", "bank_reversal", "drag_energy_guidance",
           "drag_energy_tracking", "fnpeg_guidance", "lifetime", "monitors", "native_plant", "navigation",
           "reference_tracking", "replan_scheduler", "replanning_guidance", "schedule", "swarm_bank_guidance",
           "vehicle"]
