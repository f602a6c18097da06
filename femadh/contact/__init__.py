"""Nonlinear surface problem: effects + gap constraint + elastic surface operator."""
from .problem import ContactProblem, State
from .newton import solve_state
from .continuation import Sweep, Jump, trace

__all__ = ["ContactProblem", "State", "solve_state", "Sweep", "Jump", "trace"]
