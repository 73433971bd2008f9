"""What a person reads: the report's content (JSON), its HTML page, the terminal
summary and the figures (``report.plots``, one module per subject)."""
