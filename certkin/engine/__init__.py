"""The one branch-and-bound engine used by every solver (see ``search``)."""
from .search import (CONTRACTED, EXCLUDED, OPEN, PROVED, SPLIT, UNDECIDED, Budget, Decisions, SearchResult, Tree,
                     search)

__all__ = ["search", "Budget", "Decisions", "SearchResult", "Tree", "OPEN", "PROVED", "EXCLUDED", "UNDECIDED",
           "SPLIT", "CONTRACTED"]
