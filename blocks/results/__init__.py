"""Results: a run's logged signals, its record, and the files of a results folder."""
