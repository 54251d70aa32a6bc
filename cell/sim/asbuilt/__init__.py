"""The simulation's ground truth: the part as it was really built (:mod:`~cell.sim.asbuilt.parts`: the map's
parts with the scenario's deviations, placed in the world, and the fixtures where it lies), how each part's shape
is changed (:mod:`~cell.sim.asbuilt.shapes`) and the realism a shop adds (:mod:`~cell.sim.asbuilt.realism`:
tacks, bowed and twisted members). Only the simulated station reads it (and ``cell scenario check`` builds it,
for the same checks of the scenario the run makes)."""
