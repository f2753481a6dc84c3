"""Signal plots of a run's results: what to show, the diagram's markers, and pages drawn with matplotlib."""
