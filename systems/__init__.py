"""Drake LeafSystems of the entry plant, sensors, actuators and monitors."""
