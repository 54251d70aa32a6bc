"""Seams: pair each map seam with its joint (:mod:`~cell.seams.joint`), tell whether a camera can see it
(:mod:`~cell.seams.visibility`), locate it (the locators behind one signature, :mod:`~cell.seams.base`: ``paper``,
``ransac``, ``ours``; their registry :mod:`~cell.seams.registry`), check it against the aligned map
(:mod:`cell.seams.checks`), and score it against the truth (:mod:`~cell.seams.truth`, :mod:`~cell.seams.metrics`).
The values they read and return are in :mod:`cell.types`. Importers use these public modules; importing one loads
no locator it does not need. The modules with a leading underscore are this package's own.
"""
