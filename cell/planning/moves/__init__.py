"""A transfer's parts: its timed motions (:mod:`.pieces`) and the ways it may take (:mod:`.strategies`)."""
