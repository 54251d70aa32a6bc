"""The robot: its model and forward kinematics (:mod:`~cell.motion.robot`, the only Pinocchio importer), joint
limits, IK, timing (:mod:`~cell.motion.timing`, the only Ruckig importer), the wrist and the A6 hose window,
the eye-in-hand camera's scan configuration, and collisions (:mod:`cell.motion.collision`, the only coal
importer). Importers use these public modules; nothing here pulls in Pinocchio, coal or Ruckig by itself."""
