"""The JSON reports, the contract other tools read (docs/report.md): a detection's, a weld run's
(:mod:`~cell.export.reports.report`) and the parts each adds (curves, procedures, the re-scan, the journal, the
positioner, the turnover), with the values they share (:mod:`~cell.export.reports.report_values`)."""
