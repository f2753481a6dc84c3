"""The paper's three tasks: measures, figures and the one-command reproduction."""

from .reproduce import TASKS, reproduce

__all__ = ["TASKS", "reproduce"]
