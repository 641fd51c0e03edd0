"""Paper 000 drag-energy guidance as a guidance method: spec (``spec``), closed-loop systems
(``method``) and its plan report (``commands``)."""
