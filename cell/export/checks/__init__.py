"""``cell krl check``: the project's KRL reader (:mod:`~cell.export.checks.read`), the checks of one program
(:mod:`~cell.export.checks.program`), of its arm kinematics (:mod:`~cell.export.checks.kinematics`) and of a
positioner's axes (:mod:`~cell.export.checks.positioner`), and the checks across programs one controller runs
(:mod:`~cell.export.checks.calls`); docs/programs.md."""
