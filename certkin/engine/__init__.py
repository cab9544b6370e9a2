"""The one branch-and-bound engine used by every solver (``search``), its budgets and its tree."""
from .budgets import Budget
from .search import Decisions, SearchResult, search
from .tree import BUDGET, CONTRACTED, EXCLUDED, OPEN, PROVED, RESOLUTION, SPLIT, UNDECIDED, Tree

__all__ = ["search", "Budget", "Decisions", "SearchResult", "Tree", "OPEN", "PROVED", "EXCLUDED", "UNDECIDED",
           "SPLIT", "CONTRACTED", "BUDGET", "RESOLUTION"]
