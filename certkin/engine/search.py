"""The generic branch-and-bound engine shared by every solver.

A *problem* decides batches of boxes; the engine owns the frontier, the
bisection, the budgets and the record of the search tree:

    class Problem:
        reasons: tuple[str, ...]          # names of the rules, indexed by reason codes
        def decide(self, lo, hi, roots) -> Decisions
            # lo, hi: float arrays (N, d); roots: (N,) index of the initial box of each

``Decisions`` gives, per box, a status (``PROVED``, ``EXCLUDED``, ``OPEN``, or
``UNDECIDED``: given up, an undecided leaf with the problem's reason), a reason code, and evidence as a dict of arrays with one row per
box (read only for decided boxes), and optionally contracted boxes (with
their own reason and evidence): a contracted box becomes the child of the
box it came from, and the status is about the contracted box.  Open boxes are bisected
(widest side scaled by ``scale``, split off-centre at ``SPLIT_RATIO`` so
that symmetric roots do not land on faces) until they are decided, narrower
than ``min_width``, or a budget (boxes, seconds, Ctrl-C: ``interrupt``) runs out.  When few boxes
are open, each is halved several times at once (up to ``d`` times) so that
one batch keeps numpy busy; the tree still records binary splits.

A problem may return several successive contractions of a box (each inside
the previous one, e.g. a forward-backward pass then a Krawczyk step): they
become a chain of children, each with its own reason and evidence.
``initial_splits`` halves each root box that many times before the first
batch (a root box that certainly needs bisection costs one batch less).

Nothing is dropped: every box of the domain ends in exactly one leaf of the
returned ``Tree`` with status ``proved``, ``excluded`` or ``undecided`` (and
why).  All bookkeeping is done on arrays, never per box in Python.  The
frontier is a stack processed ``batch`` boxes at a time, last in first
out, so memory stays bounded by about ``batch * 2^d * depth`` boxes.  With ``independent``, each
root has its own stack and its own batches, as if searched alone (the batches of several roots are
decided in one call of about ``batch`` boxes): a root's subtree is then the one its own search makes,
whatever the other roots, provided the problem decides a box from that box and its root only; the
frontier is bounded per root as above.
Results are deterministic: the order of work depends only on the input (when the last seconds
of a time budget would not cover a whole batch, the batch is shortened; a search stopped by its
time budget depends on the machine's speed anyway).  The record of the search (tree and evidence)
and the problem's working memory for a batch (``problem.bytes_per_box``, if it has one, times the
batch's boxes: the batch is shortened to fit) stay below ``budget.max_memory``: a search that would
exceed it stops, its open boxes undecided.
"""
from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
import time

import numpy as np

from . import interrupt
from .budgets import Budget
from .tree import BUDGET, CONTRACTED, EXCLUDED, INTERRUPTED, NOT_NEEDED, OPEN, PROVED, RESOLUTION, SPLIT, UNDECIDED, \
    Evidence, Store, Tree

SPLIT_RATIO = 0.4921875  # off-centre bisection ratio (exact in binary)
MIN_BATCH = 16           # boxes of the smallest batch a budget leaves


@dataclass
class Decisions:
    """What a problem says about a batch of N boxes."""

    status: np.ndarray                      # (N,) int8: OPEN | PROVED | EXCLUDED, or UNDECIDED: given up
                                            # (a leaf with the problem's reason; nothing claimed about it)
    reason: np.ndarray                      # (N,) int: index into problem.reasons (decided boxes)
    evidence: dict = field(default_factory=dict)   # name -> array (N, ...), rows of decided boxes
    contracted: tuple | list | None = None  # optional (lo, hi) (N, d): the boxes after contraction (or a
                                            # list of them: successive contractions, each inside the one
                                            # before, with lists of reasons and evidence); the
                                            # statuses above are about these contracted boxes
    contraction_reason: np.ndarray | None = None   # (N,) int, for the contracted boxes
    contraction_evidence: dict = field(default_factory=dict)  # name -> array (N, ...)
    finished: np.ndarray | None = None      # roots whose answer is known: stop working on them
    split: np.ndarray | None = None         # optional (N,) preferred dimension to bisect each open box
    split_at: np.ndarray | None = None      # optional (N,) preferred cut on that dimension (NaN: none);
                                            # a box cut there is not halved again in the same round
    keep_narrow_evidence: bool = False      # also record the evidence of open boxes too narrow to split


@dataclass
class SearchResult:
    tree: Tree
    boxes: int                              # boxes decided by the problem
    seconds: float
    exhausted: bool                         # a budget ran out
    boxes_per_root: np.ndarray | None = None  # (M,) boxes decided, per root


def choose_split(lo, hi, scale):
    """Per box, the dimension with the widest scaled side and that width."""
    w = (hi - lo) / scale
    return np.argmax(w, axis=1), np.max(w, axis=1)


def search(problem, lo, hi, scale=None, budget: Budget | None = None, batch: int = 4096,
           progress=None, min_batch: int = 256, max_rounds: int | None = None,
           initial_splits: int = 0, record_limit: int | None = None, record_sink=None,
           independent: bool = False) -> SearchResult:
    """Branch and bound from the boxes ``[lo, hi]`` (arrays (M, d), one per root).

    ``progress(processed_boxes, frontier_size)`` is called after each batch.  ``min_batch``: when fewer
    boxes than this are open after a batch, each is halved several times at once (up to ``max_rounds``
    times, default d).  ``initial_splits``: each root box wide enough is first halved this many times
    without being decided (a root box of a search that needs bisection anyway costs one batch less).
    ``record_limit``: once the tree holds more nodes than this, it stops being a full record:
    excluded leaves and inner nodes are forgotten (``Store.compact``), only open, proved and
    undecided nodes are kept, and ``Tree.complete_record`` is false (the answer is the same; a
    certificate needs the search run again, with a sink or no limit).  Memory then stays bounded.
    ``record_sink(tree, roots)``: at each compaction, writes the segment of the record (a ``Tree`` view)
    at ``roots`` and returns its *continued* leaves (the nodes still held) in its order: the next
    segment's roots.  The tree returned is the last segment (``tree.segment_roots``, ``tree.record_sink``).
    ``record_sink.kept(name, kind, reason)``, if any: which evidence rows are recorded at all.
    ``scale``: (d,), or (M, d) one row per root (default: the extent of the first root's box; with
    ``independent``, of each root's box).
    ``independent``: each root is searched as if alone (its own stack, batches of up to ``batch`` of its
    boxes, ``min_batch`` counted on its boxes, ``budget.max_boxes`` its own); the batches of several
    roots are decided together, whole, in one call of up to about ``batch`` boxes.  With a problem
    whose decisions about a root's boxes depend only on those boxes, each root's subtree (and its
    count in ``SearchResult.boxes_per_root``) is then the one a search of that root alone makes,
    unless the seconds or memory ran out or may have shortened a batch of it (``tree.pressed``).
    """
    budget = budget or Budget()
    lo = np.atleast_2d(np.asarray(lo, dtype=np.float64))
    hi = np.atleast_2d(np.asarray(hi, dtype=np.float64))
    m, d = lo.shape
    if scale is None:                       # (the first root's extent; ``independent``: each root's own)
        scale = np.where(hi > lo, hi - lo, 1.0) if independent else np.where(hi[0] > lo[0], hi[0] - lo[0], 1.0)
    scale = np.asarray(scale, dtype=np.float64)
    store, compacted = Store(d, max(1024, 4 * m), m), False
    evidence = _evidence(store, record_sink)
    roots = segment = store.add(lo, hi, np.arange(m), np.full(m, -1))
    lanes = _Lanes(store, _initial(store, roots, lo, hi, scale, budget.min_width, initial_splits), m, independent)
    finished = np.zeros(m, dtype=bool)
    per_root, pressed = np.zeros(m, dtype=np.int64), np.zeros(m, dtype=bool)  # boxes decided; ``_pressed``
    processed = 0
    t0 = time.perf_counter()
    per_box = 0.0                           # seconds per box of the last batch
    exhausted, stopped, out_of_boxes = False, None, False
    work = getattr(problem, "bytes_per_box", 0)      # the problem's working memory per box of a batch
    while lanes:
        left = budget.max_seconds - (time.perf_counter() - t0)
        room = budget.max_memory - _memory(store, evidence)
        stopped = _stopped(budget, 0 if independent else processed, left, room, work)
        if stopped:
            exhausted = True
            break
        size = _batch_size(batch, per_box, left, 1 << 62 if independent else budget.max_boxes - processed,
                           room // work if work else None)
        ids, over = lanes.pop(size, batch, budget.max_boxes - per_root)
        store.kind[over], store.reason[over] = UNDECIDED, BUDGET    # roots whose own box budget ran out
        out_of_boxes |= len(over) > 0
        pressed |= _pressed(store, ids, room, budget.max_memory, work, m) if independent else False
        done = finished[store.root[ids]]
        if done.any():
            store.kind[ids[done]] = UNDECIDED
            store.reason[ids[done]] = NOT_NEEDED
            ids = ids[~done]
        if not len(ids):
            lanes.settle()
            continue
        blo, bhi = store.lo[ids], store.hi[ids]
        t_batch = time.perf_counter()
        dec = problem.decide(blo, bhi, store.root[ids])
        per_box = (time.perf_counter() - t_batch) / len(ids)
        processed += len(ids)
        _count(per_root, store.root[ids])
        ids, blo, bhi, open_ = _record(store, evidence, dec, ids, blo, bhi, finished)
        oids, olo, ohi = ids[open_], blo[open_], bhi[open_]
        if len(oids):
            prefer = None if dec.split is None else np.asarray(dec.split)[open_]
            cut = None if dec.split_at is None else np.asarray(dec.split_at, dtype=np.float64)[open_]
            new = _split(store, oids, olo, ohi, scale, budget.min_width, min_batch, prefer, max_rounds or d, cut,
                         independent)
            if dec.keep_narrow_evidence:
                narrow = store.kind[oids] == UNDECIDED
                if narrow.any():
                    evidence.add(oids[narrow], dec.evidence, np.nonzero(open_)[0][narrow])
            lanes.push(new)
        lanes.settle()
        if record_limit is not None and store.n > record_limit:
            frontier, segment = _compact(store, evidence, lanes.arrays(), segment, record_sink, problem)
            lanes.replace(frontier)
            compacted = True
        if progress:
            progress(processed, lanes.size())
    for ids in lanes.arrays():
        store.kind[ids] = UNDECIDED
        store.reason[ids] = INTERRUPTED if interrupt.requested() else BUDGET
    ev, rows = evidence.finish(store.n)
    tree = Tree(store, m, getattr(problem, "reasons", ()), ev, rows, complete_record=not compacted or bool(record_sink))
    tree.segment_roots, tree.record_sink = (segment, record_sink) if compacted and record_sink else (None, None)
    tree.stopped_by = stopped or ("boxes" if out_of_boxes else None)
    tree.spent, tree.pressed = (per_root >= budget.max_boxes, pressed) if independent else (None, None)
    return SearchResult(tree, processed, time.perf_counter() - t0, exhausted or out_of_boxes, per_root)


def _count(per_root, roots) -> None:
    """``per_root[r]`` += how many of ``roots`` are r (one pass over ``roots`` when the roots are many)."""
    if len(per_root) > 64 * len(roots):
        np.add.at(per_root, roots, 1)
    else:
        per_root += np.bincount(roots, minlength=len(per_root))


def _initial(store, roots, lo, hi, scale, min_width, initial_splits):
    """The boxes to decide first: each root box wide enough halved ``initial_splits`` times."""
    if initial_splits > 0:
        wide = np.max((hi - lo) / scale, axis=1) > min_width * 2.0 ** initial_splits   # (scale: (d,) or (m, d))
        if wide.any():
            pieces = _split(store, roots[wide], lo[wide], hi[wide], scale, min_width,
                            int(wide.sum()) << initial_splits, None, initial_splits)
            return np.concatenate([pieces, roots[~wide]])
    return roots


def _record(store, evidence, dec, ids, blo, bhi, finished):
    """Record a problem's decisions on the boxes ``ids`` (their contractions as children, the decided
    leaves with their reasons and evidence, the boxes of finished roots as not needed); returns the
    ids and boxes the decisions apply to and the mask of those still open."""
    if dec.contracted is not None:   # contracted boxes become children; the decisions apply to them
        ids, blo, bhi = _contractions(store, evidence, dec, ids, blo, bhi)
    status = np.asarray(dec.status)
    decided = status != OPEN
    store.kind[ids[decided]] = np.where(status[decided] == PROVED, PROVED,
                                        np.where(status[decided] == UNDECIDED, UNDECIDED, EXCLUDED))
    store.reason[ids[decided]] = np.asarray(dec.reason)[decided]
    evidence.add(ids[decided], dec.evidence, np.nonzero(decided)[0])
    if dec.finished is not None and len(dec.finished):
        finished[np.asarray(dec.finished, dtype=np.int64)] = True
    stop = ~decided & finished[store.root[ids]]
    store.kind[ids[stop]] = UNDECIDED
    store.reason[ids[stop]] = NOT_NEEDED
    return ids, blo, bhi, ~decided & ~stop


def _pressed(store, ids, room, max_memory, work, m):
    """The roots of ``ids`` (a batch of ``independent`` lanes) whose batch a search of that root alone
    may have shortened or not made for want of memory.  That search holds at most 1.5 times the
    memory held here plus 1536 nodes: its nodes and evidence are among those here, and its columns
    hold at most 1.5 times its nodes (they grow by half) or 1024."""
    if not work or not len(ids):
        return False
    alone = max_memory - 1.5 * (max_memory - room) - 1536 * store.nbytes() / len(store.root)
    n = np.bincount(store.root[ids], minlength=m)
    return (n > 0) & (alone < np.maximum(n, MIN_BATCH) * work)


def _stopped(budget: Budget, processed: int, left: float, room: int, work: int) -> str | None:
    """What ends a search before its next batch: "boxes", "seconds" or "memory" (its budget ran out),
    "interrupt" (Ctrl-C: the interrupt is then cut, ``interrupt.cut``), or None."""
    if processed >= budget.max_boxes:
        return "boxes"
    if left <= 0:
        return "seconds"
    if room < MIN_BATCH * work or room <= 0:
        return "memory"
    if interrupt.requested():
        interrupt.cut()
        return "interrupt"
    return None


def _contractions(store, evidence, dec, ids, blo, bhi):
    """Record the contractions of a decision: each box that changed gets its contracted box as its
    one child (a chain of children for successive contractions).  Returns the ids and boxes the
    decisions apply to."""
    if isinstance(dec.contracted, list):
        stages = zip(dec.contracted, dec.contraction_reason, dec.contraction_evidence)
    else:
        stages = [(dec.contracted, dec.contraction_reason, dec.contraction_evidence)]
    for (clo, chi), creason, cev in stages:
        changed = np.nonzero(np.any((clo != blo) | (chi != bhi), axis=1))[0]
        if len(changed):
            parents = ids[changed]
            kids = store.add(clo[changed], chi[changed], store.root[parents], parents)
            store.kind[parents] = CONTRACTED
            store.first_child[parents] = kids
            store.reason[parents] = np.asarray(creason)[changed]
            evidence.add(parents, cev, changed)
            ids = ids.copy()
            ids[changed] = kids
            blo, bhi = clo, chi
    return ids, blo, bhi


def _evidence(store, sink) -> Evidence:
    """The search's evidence record: every row, or those ``sink.kept(name, kind, reason)`` keeps."""
    kept = getattr(sink, "kept", None)
    return Evidence(kept and (lambda name, ids: kept(name, store.kind[ids], store.reason[ids])))


def _compact(store, evidence, frontier, segment, sink, problem):
    """Forget the excluded leaves and inner nodes (after handing them to ``sink``, if any); returns
    the frontier and the roots of the next segment (``sink``'s continued leaves) with the new ids."""
    kind = store.kind[:store.n]
    keep = np.zeros(store.n, dtype=bool)
    keep[(kind == PROVED) | (kind == UNDECIDED)] = True
    for ids in frontier:
        keep[ids] = True
    if sink:
        segment = np.asarray(sink(Tree.view(store, getattr(problem, "reasons", ()), evidence), segment), np.int64)
        held = np.zeros(store.n, dtype=bool)
        held[segment] = True
        if len(segment) != keep.sum() or np.any(held != keep):
            raise RuntimeError("record sink: its continued leaves are not the nodes the search holds")
    new = store.compact(np.nonzero(keep)[0], evidence)
    return [new[ids] for ids in frontier], new[segment] if sink else segment


def _memory(store, evidence) -> int:
    """Bytes the record may hold after its next growth (the columns grow by half, copied one at a time)."""
    return int(1.5 * store.nbytes()) + evidence.nbytes


def _batch_size(batch, per_box, seconds_left, boxes_left, memory_boxes=None):
    """The next batch: ``batch`` boxes, fewer when the budget's last seconds or boxes would not
    cover them (so a time budget is overrun by about one small batch, not one large one), or when the
    memory left beside the record (``memory_boxes`` boxes of the problem's working memory) would not."""
    if per_box > 0 and batch * per_box > seconds_left:
        batch = int(max(MIN_BATCH, min(batch, seconds_left / per_box)))
    if memory_boxes is not None:
        batch = min(batch, max(MIN_BATCH, memory_boxes))
    return int(max(1, min(batch, boxes_left)))


class _Lanes:
    """The frontier: one stack of id arrays, its end processed first; with ``independent``, one stack
    per root (a lane), the lanes taken in turn, each with its own whole batch."""

    def __init__(self, store, ids, m: int, independent: bool):
        self.store, self.independent = store, independent
        self.stacks = [[] for _ in range(m if independent else 1)]
        self.count = np.zeros(len(self.stacks), dtype=np.int64)     # ids held per lane
        self.queue, self.taken = deque(), []
        self.queued = np.zeros(len(self.stacks), dtype=bool)       # in the queue, or taken and not settled
        self.push(ids)
        self.settle()

    def __bool__(self):
        return bool(self.queue)

    def size(self) -> int:
        return int(self.count.sum())

    def pop(self, size: int, batch: int, room):
        """The next batch of ids (at most ``size``, or one lane's batch of at most ``batch``, those of
        the root with ``room`` boxes left); and the ids of the lanes with no room left (``independent``)."""
        if not self.independent:
            self.queue.popleft()
            self.taken.append(0)
            ids = _pop(self.stacks[0], size)
            self.count[0] -= len(ids)
            return ids, _NONE
        out, over, total = [], [], 0
        while self.queue:
            k = self.queue[0]
            n = int(min(batch, room[k], self.count[k]))
            if n <= 0:                       # this root's own box budget is spent
                self.queue.popleft()
                over += self.stacks[k]
                self.stacks[k], self.count[k], self.queued[k] = [], 0, False
                continue
            if out and total + n > size:
                break
            self.queue.popleft()
            out.append(_pop(self.stacks[k], n))
            self.count[k] -= n
            total += n
            self.taken.append(k)
        return (np.concatenate(out) if out else _NONE), (np.concatenate(over) if over else _NONE)

    def push(self, ids) -> None:
        """Open ids on top of their stack (each root's in their order: the first processed last)."""
        if not len(ids):
            return
        if not self.independent:
            self.stacks[0].append(ids[::-1])
            self.count[0] += len(ids)
            self._wake(0)
            return
        r = self.store.root[ids]
        order = np.argsort(r, kind="stable")
        r, ids = r[order], ids[order]
        cuts = np.flatnonzero(r[1:] != r[:-1]) + 1
        for k, part in zip(r[np.concatenate([[0], cuts])].tolist(), np.split(ids, cuts)):
            self.stacks[k].append(part[::-1])
            self.count[k] += len(part)
            self._wake(k)

    def _wake(self, k: int) -> None:
        if not self.queued[k]:
            self.queued[k] = True
            self.taken.append(k)

    def settle(self) -> None:
        """The lanes just worked on (or filled) back in the queue, when they hold ids."""
        for k in self.taken:
            if self.count[k]:
                self.queue.append(k)
            else:
                self.queued[k] = False
        self.taken = []

    def arrays(self) -> list:
        return [a for stack in self.stacks for a in stack]

    def replace(self, arrays) -> None:
        """The same stacks, their ids renumbered (``arrays``: as ``arrays()`` gave them)."""
        it = iter(arrays)
        self.stacks = [[next(it) for _ in stack] for stack in self.stacks]


_NONE = np.zeros(0, dtype=np.int64)


def _pop(frontier, batch):
    """Up to ``batch`` ids from the top of the stack."""
    out = []
    need = batch
    while frontier and need > 0:
        top = frontier[-1]
        if len(top) <= need:
            out.append(top)
            need -= len(top)
            frontier.pop()
        else:
            out.append(top[-need:])
            frontier[-1] = top[:-need]
            need = 0
    return np.concatenate(out[::-1]) if len(out) > 1 else out[0]


def _split(store, ids, lo, hi, scale, min_width, min_batch, prefer=None, max_rounds=None, cut=None, per_root=False):
    """Bisect the open boxes (several times each when they are few; ``per_root``: when their root's
    are few); returns the new open ids (each root's in the order a split of its boxes alone gives).

    ``prefer``: the problem's choice of dimension per box for the first halving
    (-1: the widest scaled side), used when that side is wider than ``min_width``.
    ``cut``: the problem's choice of cut on that dimension (NaN: none), used when
    strictly inside the side; such boxes are cut once.
    """
    d = lo.shape[1]
    rounds, own = _rounds(np.array([len(ids)]), min_batch, max_rounds or d)[0], None
    if per_root and len(ids):               # the rounds of each box: those of its root's boxes
        _, at_root, per = np.unique(store.root[ids], return_inverse=True, return_counts=True)
        own = _rounds(per, min_batch, max_rounds or d)[at_root]
        rounds = own.max()
    kept = []                               # fresh pieces not split in a later round: still open
    for r in range(rounds):
        if own is not None and r > 0 and np.any(own <= r):     # the pieces of roots with no more rounds
            last = own <= r
            kept.append(ids[last])
            ids, lo, hi, own = ids[~last], lo[~last], hi[~last], own[~last]
        if not len(ids):
            break
        sc = np.broadcast_to(scale, lo.shape) if scale.ndim == 1 else scale[store.root[ids]]
        dims, widths = choose_split(lo, hi, sc)
        rows = np.arange(len(ids))
        if r == 0 and prefer is not None:
            p = np.maximum(prefer, 0)
            w_pref = (hi[rows, p] - lo[rows, p]) / sc[rows, p]
            use = (prefer >= 0) & (w_pref > min_width)
            dims = np.where(use, prefer, dims)
        a, b = lo[rows, dims], hi[rows, dims]
        at = a + SPLIT_RATIO * (b - a)
        hinted = None
        if r == 0 and cut is not None:
            hinted = np.isfinite(cut) & (a < cut) & (cut < b)
            at = np.where(hinted, cut, at)
        ok = (a < at) & (at < b) & (widths > min_width)
        if not ok.all():
            if r == 0:  # an evaluated box too narrow to split: an undecided leaf
                store.kind[ids[~ok]] = UNDECIDED
                store.reason[ids[~ok]] = RESOLUTION
            else:       # a fresh piece, not evaluated yet: it stays open
                kept.append(ids[~ok])
            ids, lo, hi, dims, at = ids[ok], lo[ok], hi[ok], dims[ok], at[ok]
            hinted = None if hinted is None else hinted[ok]
            own = None if own is None else own[ok]
            rows = np.arange(len(ids))
        clo = np.repeat(lo, 2, axis=0)
        chi = np.repeat(hi, 2, axis=0)
        chi[2 * rows, dims] = at            # lower halves
        clo[2 * rows + 1, dims] = at        # upper halves
        kids = store.add(clo, chi, np.repeat(store.root[ids], 2), np.repeat(ids, 2))
        store.kind[ids] = SPLIT
        store.split_dim[ids] = dims
        store.split_at[ids] = at
        store.first_child[ids] = kids[0::2]
        ids, lo, hi = kids, clo, chi
        own = None if own is None else np.repeat(own, 2)
        if hinted is not None and hinted.any():       # boxes cut at the problem's point: not halved again
            twice = np.repeat(hinted, 2)
            kept.append(ids[twice])
            ids, lo, hi = ids[~twice], lo[~twice], hi[~twice]
            own = None if own is None else own[~twice]
    if kept:
        ids = np.concatenate(kept + [ids])
    return ids


def _rounds(n, min_batch: int, max_rounds: int) -> np.ndarray:
    """How many times to halve each of ``n`` open boxes so that about ``min_batch`` are open (at most
    ``max_rounds``; once when none or enough are open)."""
    n = np.asarray(n, dtype=np.float64)
    few = (n > 0) & (n < min_batch)
    many = np.ceil(np.log2(min_batch / np.where(few, n, 1.0)))
    return np.where(few, np.minimum(max_rounds, np.maximum(1, many)), 1).astype(np.int64)
