"""What the commands print from their JSON reports, so screen and file agree: the tables and summary lines
(:mod:`~cell.cli.printout.tables`, the re-scan's :mod:`~cell.cli.printout.rescan_table`) and a partial run's last
line (:mod:`~cell.cli.printout.explain`)."""
