"""The one branch-and-bound engine used by every solver (see ``search``)."""
from .search import EXCLUDED, OPEN, PROVED, SPLIT, Budget, Decisions, Node, SearchResult, search

__all__ = ["search", "Budget", "Decisions", "Node", "SearchResult", "OPEN", "PROVED", "EXCLUDED", "SPLIT"]
