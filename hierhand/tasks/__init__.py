"""The paper's three tasks: summaries, sweep measures, figures and the
one-command reproduction."""

from .reproduce import TASKS, reproduce

__all__ = ["TASKS", "reproduce"]
