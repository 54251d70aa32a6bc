"""The weld process as the torch sees it: torch poses and their candidates within the process tolerances, the
weave, the weld procedures and their passes, the table stand-off, and how well a weld was made."""
