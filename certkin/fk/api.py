"""``forward_kinematics``: every real assembly mode for given leg lengths, each in a box proved to
hold exactly one; ``track_sequence``: the posture followed through a sequence of leg lengths.

With a previous pose (``track=``), tracking (``fk.tracking``) proves the posture near it first;
what it could not prove goes to the branch-and-bound search (``fk.search``), never to a guess.
The proved leaves of the search are then turned into distinct roots (``_merge``: boxes proved
unique whose root boxes lie in one another's uniqueness box share their root; for a quaternion,
q and −q are one posture, a *twin*); each root is a *region*: a uniqueness box X* and a root
box R inside it.  Leaves left at the resolution limit, or given up inside a root's spread over
uncertain leg lengths, are grouped into *clusters* (status ``cluster``: any number of postures,
none proved; near-singular roots, double roots); other undecided boxes (a budget ran out) into
``unresolved`` regions.  Neither is ever reported as two roots nor as none.  ``complete`` is
true when every box of the domain was excluded, proved or left in a cluster, and every root's
box lies inside the domain or outside it: every posture is then in a solution box or a cluster.
"""
from __future__ import annotations

from dataclasses import replace
import math
import time

import numpy as np

from intervals import Interval, sqr

from .. import display
from ..engine import BUDGET, PROVED, RESOLUTION, UNDECIDED, Budget, budgets
from ..certificates.fk import record_sink
from ..engine.budgets import make_budget, positive_integer, progress_callback
from ..errors import InputError, shown
from ..quiet import quiet
from ..robots import as_robot
from ..robots.poses import MAX_MAGNITUDE, length_enclosures, parse_box
from .angles import in_ranges
from .result import FKResult, described
from .search import FKProblem, search_instances
from .step import root_boxes
from .system import fk_system
from .tracking import track_one, track_rows


@quiet
def forward_kinematics(robot, lengths, domain=None, budget: Budget | None = None, progress=None, track=None, *,
                       max_boxes=None, max_seconds=None, min_width=None, max_memory=None, record: bool | str = False,
                       record_limit: int | None = None, independent: bool = False):
    """All real FK postures for the leg lengths ``lengths``.

    ``robot``: a robot or a robot file's path.  The budget: ``budget`` or the keywords
    ``max_boxes``, ``max_seconds``, ``min_width``, ``max_memory``.  ``lengths``: one set (sequence or "l1,l2,..." text), or a 2-D array with
    one row per instance (then a list of results is returned; the instances
    are searched together, as one batch); a numpy masked array is taken only with nothing masked
    (a masked entry is an ``InputError``: it has no value to certify).  ``domain``: optional box of pose
    variables (``"x=a:b,..."``); position ranges narrow the search, angle
    ranges filter the solutions.  ``track``: a previous pose; the unique
    posture near it is proved directly when possible (``result.tracked``),
    else the full search runs; with a 2-D ``lengths`` the rows are a
    sequence, tracked one after another from ``track`` (``track_sequence``).
    Each solution is proved unique in its box; ``complete`` means the rest of
    the domain is proved empty.  ``record``: keep the whole search tree however large (for a
    certificate): a search past ``record_limit`` nodes (a positive integer, default ``budgets.FK_RECORD_NODES``) hands
    each closed part to a temporary file (``certificates.segments``), or keeps it in memory with
    ``record="whole"``; without ``record`` it forgets its excluded leaves and ``fk_certificate``
    runs it again with ``record``.  ``progress``: None or a callable ``progress(boxes, frontier)``
    (else ``InputError``).  ``independent`` (2-D ``lengths``): each row is searched as if alone, with the
    budget of one instance (``max_boxes`` each; the seconds and memory are shared): a row's answer and
    its box count are then those of its own call, unless the seconds or memory ran out or the memory
    may have shortened a batch of its own call (``result.tree.pressed``).  The rows are still decided
    together, a batch at a time: a small planar row takes about 6 ms against 40 ms alone, and 3.7 ms
    with the default, which shares its bisection among the rows (a row's answer then depends on the
    others, never its soundness).  The rows' answers take ``ROW_SECONDS`` each after the search, kept
    from its seconds: more rows than ``max_seconds`` can answer are refused (``InputError``).  The
    unresolved regions of an incomplete answer are described in a share of the seconds kept too
    (``UNRESOLVED_SHARE``): with little time left, fewer and larger ones (at least ``MIN_UNRESOLVED``).
    numba's start-up in a spatial search (about 1 s the first time in a process) is not counted in
    ``max_seconds``; compiling the kernels (once per machine) and loading the last of them are.
    """
    started = time.perf_counter()
    progress = progress_callback(progress)
    if record_limit is not None:
        record_limit = positive_integer(record_limit, "record_limit")
    if not (record is True or record is False or isinstance(record, str) and record == "whole"):
        raise InputError("record", "", f"expected True, False or \"whole\", got {shown(record)}")
    if not isinstance(independent, (bool, np.bool_)):
        raise InputError("independent", "", f"expected True or False, got {shown(independent)}")
    robot = as_robot(robot)
    keywords = dict(max_boxes=max_boxes, max_seconds=max_seconds, min_width=min_width, max_memory=max_memory)
    if track is not None and domain is not None:      # (the tracked posture was returned outside the domain)
        raise InputError("domain", "", "not with track (a tracked posture is proved near the previous pose, not "
                                       "searched in a domain)")
    if track is not None and not isinstance(lengths, str) and np.asarray(lengths, dtype=object).ndim == 2:
        return track_sequence(robot, lengths, track, budget=budget, **keywords)
    system = fk_system(robot)
    rho, texts, batch_input = length_enclosures(robot, lengths)
    M = len(texts)
    budget = make_budget({**budgets.FORWARD_KINEMATICS, "max_boxes": max(budgets.FORWARD_KINEMATICS["max_boxes"],
                                                                         budgets.FK_BOXES_PER_INSTANCE * (1 if independent else M))},
                         budget, **keywords)
    reserve = ROW_SECONDS * M                   # the rows' answers, after the search: kept from its seconds
    if M > 1 and reserve > budget.max_seconds:  # (one row: a budget spent gives an incomplete answer)
        raise InputError("max_seconds", "", f"{M} rows of leg lengths take about {reserve:.3g} s to answer after the "
                                            f"search, more than the time budget ({budget.max_seconds:g} s): give more, "
                                            "or fewer rows at a time")
    L = sqr(rho)
    if track is not None and not batch_input:
        result = track_one(robot, system, texts[0], L, track)     # seed 002 §4: the posture near the previous one
        if result is not None:
            return result
    lo, hi = system.domain(rho)
    angle_filter = None
    if domain is not None:
        lo, hi, angle_filter = _apply_domain(robot, system, domain, lo, hi)
    feasible = np.all(lo <= hi, axis=1)
    started += _loading_seconds(system, feasible)    # start-up, as the imports: not counted
    t0 = time.perf_counter()
    idx = np.nonzero(feasible)[0]
    limit = None if record == "whole" else budgets.FK_RECORD_NODES if record_limit is None else record_limit
    reserve += min(UNRESOLVED_SHARE * budget.max_seconds, MAX_UNRESOLVED * UNRESOLVED_SECONDS)   # (if incomplete)
    searched = replace(budget.within(budget.max_seconds - (time.perf_counter() - started) - reserve),
                       max_memory=max(1, int(SEARCH_SHARE * budget.max_memory)))
    res = search_instances(system, Interval.from_bounds(L.lo[idx], L.hi[idx]), lo[idx], hi[idx], searched, progress,
                           limit, record_sink(system.n, FKProblem.reasons) if record and limit is not None else None,
                           independent=bool(independent)) if len(idx) else None
    out = _collect(robot, system, texts, lo, hi, L, feasible, idx, res, angle_filter, started + budget.max_seconds)
    if independent and res is not None:       # each row's boxes decided, as its own call counts them
        for k, i in enumerate(idx):
            out[i].boxes = int(res.boxes_per_root[k])
    again = {}
    for k, r in enumerate(out):
        r.user_domain = domain is not None
        r.domain_text = None if domain is None else _domain_text(domain)
        if res is not None and (not res.tree.complete_record or res.tree.record_sink):   # for a certificate
            r.recorded = lambda whole=False, k=k: _again(robot, lengths, domain, budget, record_limit, k, whole, again,
                                                         independent)
    seconds = time.perf_counter() - t0
    for r in out:
        r.seconds = seconds / M
    if not batch_input:
        out[0].boxes = res.boxes if res else 0
        return out[0]
    return out


def _again(robot, lengths, domain, budget, record_limit, k, whole, cache, independent=False):
    """The k-th result of the same query, its search tree streamed (or kept ``whole``), searched once."""
    if whole not in cache:
        cache[whole] = forward_kinematics(robot, lengths, domain=domain, budget=budget, record="whole" if whole else True,
                                          record_limit=record_limit, independent=independent)
    out = cache[whole]
    return out[k] if isinstance(out, list) else out


@quiet
def track_sequence(robot, lengths_rows, start_pose, fallback: bool = True, budget: Budget | None = None, *,
                   max_boxes=None, max_seconds=None, min_width=None, max_memory=None):
    """Track the posture through a sequence of leg-length sets from ``start_pose``: one result per
    row, each step proved unique near the previous step's posture (``result.tracked``), all proofs
    in one batched evaluation (``fk.tracking.track_rows``).  Steps that are not proved get the full
    search (``fallback``: all postures, ``tracked`` false; the steps needing it are searched
    together as one batch, with ``budget``), or are reported not proved (no solution, ``complete``
    false)."""
    robot = as_robot(robot)
    if not isinstance(fallback, (bool, np.bool_)):
        raise InputError("fallback", "", f"expected True or False, got {fallback!r:.40}")
    make_budget(budgets.FORWARD_KINEMATICS, budget, max_boxes=max_boxes, max_seconds=max_seconds,
                min_width=min_width, max_memory=max_memory)      # a bad budget is refused even when no search runs
    t0 = time.perf_counter()
    results, missing = track_rows(robot, lengths_rows, start_pose)
    if missing and fallback:
        searched = forward_kinematics(robot, [list(results[k].lengths) for k in missing], budget=budget,
                                      max_boxes=max_boxes, max_seconds=max_seconds, min_width=min_width,
                                      max_memory=max_memory)
        for k, r in zip(missing, searched):
            results[k] = r
    seconds = (time.perf_counter() - t0) / len(results)
    for r in results:
        if r.tracked or not fallback:
            r.seconds = seconds
    return results


def _loading_seconds(system, feasible) -> float:
    """Load the machine code of a spatial search (about 1 s the first time in a process: numba's
    start-up) when there is one to run, and return the seconds it took."""
    if not feasible.any() or system.kind == "planar-3rpr":
        return 0.0
    from . import cayley_menger         # (numba: spatial searches only)
    loading = time.perf_counter()
    cayley_menger.load()
    return time.perf_counter() - loading


def _collect(robot, system, texts, lo, hi, L, feasible, idx, res, angle_filter, deadline=math.inf):
    """Results per instance from the search tree (solutions merged, undecided boxes clustered; the nearer
    the ``deadline``, a ``time.perf_counter()`` value, the fewer and larger the unresolved regions)."""
    M = len(texts)
    results = [FKResult(robot, system, texts[i], (lo[i], hi[i]), user_domain=angle_filter is not None) for i in range(M)]
    for i in np.nonzero(~feasible)[0]:
        results[i].complete = True          # the leg-length balls do not meet: no posture at all
    if res is None:
        return results
    tree = res.tree
    proved = tree.leaves(kind=PROVED)
    slo, shi = tree.lo[proved].copy(), tree.hi[proved].copy()
    rows = tree.evidence_rows.get("star")
    if rows is not None:
        has = rows[proved] >= 0
        st = tree.evidence["star"][rows[proved[has]]]
        slo[has], shi[has] = st[..., 0], st[..., 1]
    inst = idx[tree.root[proved]]
    Lp = Interval.from_bounds(L.lo[inst], L.hi[inst])
    if len(proved):
        rlo, rhi, rC = root_boxes(system, slo, shi, Lp)
    else:
        rlo, rhi, rC = slo, shi, np.zeros((0, system.n, system.n))
    undecided = tree.leaves(kind=UNDECIDED)
    nodes = tree.nodes_per_root()
    by_root = np.argsort(tree.root[proved], kind="stable")
    starts = np.searchsorted(tree.root[proved][by_root], np.arange(len(idx) + 1))
    und_sorted = undecided[np.argsort(tree.root[undecided], kind="stable")]
    und_starts = np.searchsorted(tree.root[und_sorted], np.arange(len(idx) + 1))
    at_limit = (tree.reason[und_sorted] == RESOLUTION) | (tree.reason[und_sorted] == FKProblem.CLUSTER)
    star_C = tree.evidence_values("C", proved) if len(proved) else np.zeros((0, system.n, system.n))
    pendings = []
    for k, i in enumerate(idx):
        r = results[i]
        r.tree, r.node, r.boxes = tree, k, int(nodes[k])
        sel = by_root[starts[k]:starts[k + 1]]
        mine = slice(und_starts[k], und_starts[k + 1])
        r.cluster_leaves = und_sorted[mine][at_limit[mine]]
        open_ = und_sorted[mine][~at_limit[mine]]
        pending = list(zip(tree.lo[open_], tree.hi[open_]))
        if np.any(tree.reason[und_sorted[mine]] == BUDGET):
            r.message = budget_message("boxes" if tree.spent is not None and tree.spent[k] else tree.stopped_by)
        _merge(r, system, proved[sel], (slo[sel], shi[sel], star_C[sel]), rlo[sel], rhi[sel], rC[sel], lo[i], hi[i],
               pending)
        pendings.append(pending)
    # poses and platform points of every solution of every instance in one evaluation
    counts = [len(results[i].solutions) for i in idx]
    computed = [None] * len(idx)
    if sum(counts):
        boxes = [s["box"] for i in idx for s in results[i].solutions]
        B = Interval.from_bounds(np.stack([b.lo for b in boxes]), np.stack([b.hi for b in boxes]))
        poses, pts = system.pose(B), system.points(B)
        first = np.concatenate([[0], np.cumsum(counts)])
        computed = [({name: v[first[k]:first[k + 1]] for name, v in poses.items()}, pts[first[k]:first[k + 1]])
                    for k in range(len(idx))]
    for k, i in enumerate(idx):
        _finish(results[i], system, pendings[k], angle_filter, computed[k], deadline)
    return results


def _meets(alo, ahi, blo, bhi):
    return bool(np.all(alo <= bhi) and np.all(blo <= ahi))


def _merge(result, system, leaves, stars, rlo, rhi, rC, dlo, dhi, pending):
    """Distinct roots (postures) from the proved leaves of one instance.

    A leaf joins the root of an earlier group when that group's root box lies
    in the leaf's uniqueness box X* (or, for a quaternion, the root box with q
    negated: the same posture, a ``twin``); otherwise it starts a group with
    its own root box.  Groups whose boxes lie in the domain and are disjoint
    from every other group's box (and its negation) are the solutions.
    Each group is a *region* (``result.regions``): the X* of the leaf that started it (with that
    leaf's C) and the group's root box R ⊆ X*; a leaf of the group whose box lies in that X*
    is ``in_region`` (its only possible root is the region's).
    """
    slo, shi, sC = stars
    spatial = system.kind != "planar-3rpr"
    p = system.n_pos
    groups = []                              # (lo, hi, C) of each group's root box
    member = []                              # per leaf: (group, twin)
    n_leaves = len(leaves)
    glo_all, ghi_all = np.empty((n_leaves, system.n)), np.empty((n_leaves, system.n))  # rows of the groups so far
    for a in range(n_leaves):
        found = None
        g_n = len(groups)
        if g_n:
            Glo, Ghi = glo_all[:g_n], ghi_all[:g_n]
            direct = np.all((Glo >= slo[a]) & (Ghi <= shi[a]), axis=1)
            hit = direct
            if spatial:
                Nlo = np.concatenate([Glo[:, :p], -Ghi[:, p:]], axis=1)
                Nhi = np.concatenate([Ghi[:, :p], -Glo[:, p:]], axis=1)
                hit = direct | np.all((Nlo >= slo[a]) & (Nhi <= shi[a]), axis=1)
            if hit.any():                    # the first group holding the leaf's root (direct before twin)
                g = int(np.argmax(hit))
                found = (g, not bool(direct[g]))
        if found is None:
            groups.append((rlo[a], rhi[a], rC[a]))
            result.regions.append({"star": (slo[a], shi[a]), "star_C": sC[a], "box": (rlo[a], rhi[a]), "C": rC[a]})
            glo_all[g_n], ghi_all[g_n] = rlo[a], rhi[a]
            found = (g_n, False)
        member.append(found)
    status = []                              # per group: "solution", "outside" or "ambiguous"
    G = len(groups)
    Glo, Ghi = glo_all[:G], ghi_all[:G]
    meets = np.all((Glo[:, None, :] <= Ghi[None, :, :]) & (Glo[None, :, :] <= Ghi[:, None, :]), axis=-1)
    if spatial:
        Nlo = np.concatenate([Glo[:, :p], -Ghi[:, p:]], axis=1)
        Nhi = np.concatenate([Ghi[:, :p], -Glo[:, p:]], axis=1)
        meets |= np.all((Glo[:, None, :] <= Nhi[None, :, :]) & (Nlo[None, :, :] <= Ghi[:, None, :]), axis=-1)
    np.fill_diagonal(meets, False)
    outside = np.any(Ghi < dlo, axis=1) | np.any(Glo > dhi, axis=1)
    inside = np.all(Glo >= dlo, axis=1) & np.all(Ghi <= dhi, axis=1)
    for g in range(G):
        if outside[g]:
            status.append("outside")
        else:
            status.append("ambiguous" if (not inside[g] or meets[g].any()) else "solution")
        result.regions[g]["status"] = status[-1]
    across = int(np.count_nonzero(~outside & ~inside))
    if across and not result.message:
        result.message = (f"{display.counted(across, 'posture')} {'lies' if across == 1 else 'lie'} across the "
                          "boundary of the domain (reported unresolved)" +
                          (f": move the domain's bounds off {'it' if across == 1 else 'them'} to decide"
                           if result.user_domain else ""))
    index = {}
    for g, st in enumerate(status):
        glo, ghi, gC = groups[g]
        if st == "solution":
            index[g] = len(result.solutions)
            result.solutions.append({"status": "unique", "box": Interval.from_bounds(glo.copy(), ghi.copy()), "C": gC})
        elif st == "ambiguous":
            pending.append((glo, ghi))
    for a, leaf in enumerate(leaves):
        g, twin = member[a]
        region = result.regions[g]["star"]
        entry = {"star": (slo[a], shi[a]), "region": g,
                 "in_region": not twin and bool(np.all(result.tree.lo[leaf] >= region[0])
                                                and np.all(result.tree.hi[leaf] <= region[1]))}
        if status[g] == "solution":
            entry.update(solution=index[g], twin=twin)
        elif status[g] == "outside" and not twin and not _meets(groups[g][0], groups[g][1], *leaf_box(result, leaf)):
            entry.update(outside=groups[g])  # the root of X* is outside the domain, so not in this leaf
        else:
            entry.update(undecided=True)
            if status[g] == "outside":
                pending.append(leaf_box(result, leaf))
        result.leaf_proofs[int(leaf)] = entry
    result.complete = not pending


def leaf_box(result, leaf):
    return result.tree.lo[leaf], result.tree.hi[leaf]


def _finish(result, system, pending, angle_filter, computed=None, deadline=math.inf):
    """Poses and platform points of the solutions; undecided boxes clustered; the angle filter.

    ``computed``: (poses, points) of the solution boxes, if already evaluated (batched).  The open
    boxes become at most ``MAX_UNRESOLVED`` regions, fewer when ``deadline`` leaves less than
    ``UNRESOLVED_SECONDS`` each (never fewer than ``MIN_UNRESOLVED``): every box still lies in one."""
    result.all_solutions = list(result.solutions)
    if result.solutions:
        if computed is None:
            R = Interval.from_bounds(np.stack([s["box"].lo for s in result.solutions]),
                              np.stack([s["box"].hi for s in result.solutions]))
            computed = system.pose(R), system.points(R)
        kept, edge = [], 0
        for s, told in zip(result.solutions, described(result.robot, *computed)):
            s.update(told)
            verdict = in_ranges(s["pose"], angle_filter)
            if verdict is True:
                kept.append(s)
            elif verdict is False:
                result.filtered.append(s)
            else:
                pending.append((s["box"].lo, s["box"].hi))
                edge += 1
        result.solutions = kept
        if edge and not result.message:
            result.message = (f"{display.counted(edge, 'posture')} proved unique in the box searched "
                              f"{'lies' if edge == 1 else 'lie'} on an edge of the angle ranges of the domain, or where "
                              f"{'its' if edge == 1 else 'their'} angles are not determined"
                              + (" (a middle angle of 0 or pi leaves the other two free)" if system.kind != "planar-3rpr" else "")
                              + ", so not proved inside or outside them: widen the ranges to decide")
    _cluster_leaves(result, system)
    if pending:
        room = (deadline - time.perf_counter()) / UNRESOLVED_SECONDS
        limit = int(min(MAX_UNRESOLVED, max(MIN_UNRESOLVED, room)))
        hull = _clusters(np.array([p[0] for p in pending]), np.array([p[1] for p in pending]), limit)
        B = Interval.from_bounds(np.stack([h[0] for h in hull]), np.stack([h[1] for h in hull]))
        result.unresolved.extend({"box": B[j], **told}
                                 for j, told in enumerate(described(result.robot, system.pose(B), system.points(B))))
        result.complete = False
        if len(result.clusters) > 1 and (not result.message or result.message.endswith(BUDGET_MESSAGE)):
            ranges = any(":" in t for t in result.lengths)
            why = ("over the length ranges the postures sweep regions that could not be told apart (narrower "
                   "ranges resolve more)" if ranges else
                   "the postures may form a continuum (a self-motion) or be singular")
            result.message = (("the budget ran out after " if result.message else "") +
                              f"the search reached the resolution limit in {len(result.clusters)} separate places "
                              f"without proving a posture there: {why}")
    result.solutions.sort(key=lambda s: [float(v.lo) for v in s["pose"].values()])
    _twins(result, system)
    if result.clusters and not result.message:      # complete, with clusters: say what they are and how large
        result.message = _cluster_note(result)


def _twins(result, system):
    """Mark a cluster ``twin_of`` mode k (0-based) when its box with the quaternion negated lies in mode
    k's uniqueness box X*: a root (p, q) in the cluster gives the root (p, −q) in X*, which is mode k's
    one root, so the cluster holds no posture but mode k's own rotation (q and −q are one rotation).
    This happens when the twin sits on the domain's face q0 = −δ.  Exact float comparisons of negated
    bounds; the certificate still lists the cluster (what it proves is unchanged)."""
    if system.kind == "planar-3rpr" or not result.clusters:
        return
    p = system.n_pos
    stars = {(tuple(r["box"][0]), tuple(r["box"][1])): r["star"] for r in result.regions}
    for c in result.clusters:
        lo, hi = c["box"].lo, c["box"].hi
        nlo, nhi = np.concatenate([lo[:p], -hi[p:]]), np.concatenate([hi[:p], -lo[p:]])
        for k, s in enumerate(result.solutions):
            star = stars.get((tuple(s["box"].lo), tuple(s["box"].hi)))
            if star is not None and np.all(nlo >= star[0]) and np.all(nhi <= star[1]):
                c["twin_of"] = k
                break


def _cluster_note(result) -> str:
    """What the clusters of an answer are, and how much of the domain the largest covers (a cluster as
    large as the domain resolves nothing)."""
    dlo, dhi = (np.asarray(v, float) for v in result.domain)
    extent = max(float(np.max((c["box"].hi - c["box"].lo) / np.maximum(dhi - dlo, 1e-300))) for c in result.clusters)
    share = f"; the largest spans {min(extent, 1.0):.0%} of the domain in some unknown" if extent >= 0.01 else ""
    if any(":" in t for t in result.lengths):
        why = "the postures of the length ranges could not be told apart there (narrower ranges resolve more)"
    else:
        why = "a singular pose, postures closer than the resolution, or a continuum"
    k = result.system.n_pos                         # a position face of the user's domain: a posture on it
    if result.user_domain and any(np.any(c["box"].lo[:k] <= dlo[:k]) or np.any(c["box"].hi[:k] >= dhi[:k])
                                  for c in result.clusters):
        why = ("a posture on a face of the domain (not proved inside or outside it: move the domain's bounds "
               f"off it to decide), {why}")
    twins = [c for c in result.clusters if "twin_of" in c]
    twin_note = "; ".join(f"cluster {result.clusters.index(c) + 1} is mode {c['twin_of'] + 1} again (its quaternion "
                          "negated, on the domain's face q0 = -2^-10): no other posture" for c in twins)
    n = len(result.clusters) - len(twins)
    if not n:
        return twin_note
    return (f"{display.counted(n, 'cluster')} at the resolution limit, {'each ' if n > 1 else ''}holding any number "
            f"of postures: {why}{share}" + (f"; {twin_note}" if twin_note else ""))


ROW_SECONDS = 1.5e-3          # to answer one row after the search (its poses, boxes and merging; measured: 0.7 to
                              # 1.0 ms a planar row on a slow machine; a row left incomplete describes its
                              # unresolved regions on top, in the seconds kept by UNRESOLVED_SHARE)
SEARCH_SHARE = 0.65           # of max_memory, for the search's record and working memory: the answer built
                              # from its leaves took up to 17 % of the budget more (2 000 unresolved regions)
MAX_UNRESOLVED = 2000        # unresolved regions of one answer at most (its open boxes grouped: ``_clusters``)
MIN_UNRESOLVED = 16          # ... and at least, however little time is left
UNRESOLVED_SECONDS = 100e-6  # to describe one unresolved region (its pose and platform points; measured: 75 us on
                             # a slow machine); with the time budget nearly spent, fewer and larger regions
UNRESOLVED_SHARE = 0.1       # of max_seconds kept from the search for them (at most MAX_UNRESOLVED of them)
BUDGET_MESSAGE = "ran out before every region was decided"
BUDGETS = {"boxes": "the box budget", "seconds": "the time budget", "memory": "the memory budget"}
MAX_GROUPS = 2000             # groups of cluster leaves at most (``_touching``)
CUT_WORK = 64                 # ``_touching`` cuts groups for at most this many sorts of all the boxes
CLUSTER_GAP = 2.0 ** -20     # cluster leaves closer than this (relative to the domain) or than their own width join
CONTINUUM = 1000.0           # a cluster this many times longer than its leaves,
CONTINUUM_EXTENT = 2.0 ** -10  # and this long relative to the domain, suggests a continuum of postures


def _cluster_leaves(result, system):
    """``result.clusters`` from the cluster leaves (``result.cluster_leaves``): hulls of leaves within
    their own width (or ``CLUSTER_GAP`` of the domain) of each other; a solution meeting a cluster
    joins it (the certificate keeps it as a proved region).  A cluster may hold any number of
    postures: a double root at a singular pose, roots closer than the resolution, or the roots of
    a range of leg lengths that no uniqueness box holds.  ``result.cluster_of``: leaf -> cluster.
    A cluster far longer than its leaves and not small in the domain (``CONTINUUM``,
    ``CONTINUUM_EXTENT``) sets ``result.message``: the postures may form a continuum."""
    leaves = result.cluster_leaves
    if not len(leaves):
        return
    tree = result.tree
    dlo, dhi = result.domain
    width = tree.hi[leaves] - tree.lo[leaves]
    pad = np.maximum((dhi - dlo) * CLUSTER_GAP, width)
    groups = _touching(tree.lo[leaves] - pad, tree.hi[leaves] + pad)
    hulls = [[tree.lo[leaves[g]].min(axis=0), tree.hi[leaves[g]].max(axis=0)] for g in groups]
    kept = []
    for s in result.solutions:
        hit = [c for c, (a, b) in enumerate(hulls) if _meets(a, b, s["box"].lo, s["box"].hi)]
        if hit:
            hulls[hit[0]] = [np.minimum(hulls[hit[0]][0], s["box"].lo), np.maximum(hulls[hit[0]][1], s["box"].hi)]
        else:
            kept.append(s)
    result.solutions = kept
    B = Interval.from_bounds(np.stack([h[0] for h in hulls]), np.stack([h[1] for h in hulls]))
    for c, (g, told) in enumerate(zip(groups, described(result.robot, system.pose(B), system.points(B)))):
        result.cluster_of.update((int(j), c) for j in leaves[g])
        result.clusters.append({"status": "cluster", "box": B[c], "leaves": int(len(g)), **told})
        extent = B.hi[c] - B.lo[c]
        span = np.max(extent / np.maximum(np.max(width[g], axis=0), 1e-300))
        if len(g) >= 100 and span > CONTINUUM and np.max(extent / np.maximum(dhi - dlo, 1e-300)) > CONTINUUM_EXTENT:
            result.message = (f"{len(g)} boxes at the resolution limit stretch {span:.0f} times their width: "
                              "the postures may form a continuum (a self-motion); no count is given there")


def _touching(lo, hi):
    """Index groups of boxes whose hulls do not meet: the boxes are cut into groups wherever, along
    some coordinate, a gap separates them (sorted by lower end, a lower end above every upper end
    before it), and each group again, until no coordinate has a gap.  Groups in different parts lie
    on either side of a gap, so no box of one meets a box of another, nor their hulls.  A group may
    still hold boxes that do not meet, where no coordinate separates them.  (Before, groups were
    joined pairwise while their hulls met, beyond 2000 groups first in runs of neighbours along the
    first coordinate to bound the work: seed 002 with leg lengths within 1e-4 has 47 843 cluster
    leaves in 16 separate sets; the runs made them one cluster as wide as the domain, the pairwise
    joining alone took 32 s; cut at gaps, they are the 16 sets in 0.1 s.)  Any grouping is sound:
    each box lies in its group's hull.  Beyond
    ``MAX_GROUPS`` groups (a search with such leaves everywhere), runs of consecutive ones (in order
    of the first coordinate) are joined; the cutting stops after ``CUT_WORK`` times the boxes'
    sorting work, the groups not yet cut left whole."""
    n, d = lo.shape
    done, todo, work = [], [np.arange(n)], 0
    while todo:
        g = todo.pop()
        if len(g) == 1 or work > CUT_WORK * n * d:
            done.append(g)
            continue
        for k in range(d):
            order = g[np.argsort(lo[g, k], kind="stable")]
            work += len(g)
            cuts = np.nonzero(lo[order[1:], k] > np.maximum.accumulate(hi[order[:-1], k]))[0] + 1
            if len(cuts):
                todo.extend(np.split(order, cuts)[::-1])
                break
        else:
            done.append(np.sort(g))
    done.sort(key=lambda g: (float(np.min(lo[g, 0])), int(g[0])))
    if len(done) > MAX_GROUPS:
        done = [np.concatenate([done[i] for i in run]) for run in np.array_split(np.arange(len(done)), MAX_GROUPS)]
    return done


def _domain_text(spec) -> str:
    """A user domain as text, "x=a:b,..." (a dict's ranges joined the same way)."""
    if isinstance(spec, str):
        return spec.strip()
    return ",".join(f"{k}=" + (":".join(str(x) for x in v) if isinstance(v, (list, tuple)) else str(v))
                    for k, v in spec.items())


def _apply_domain(robot, system, spec, lo, hi):
    """Narrow the position unknowns to a user box; angle ranges become a solution filter.  A user
    range that misses the range the leg lengths allow is searched as it is (its emptiness proved
    there, by the search and its certificate): an empty domain is the claim that the leg lengths
    allow no posture at all, which is not what the user's box shows."""
    if (isinstance(spec, str) and not spec.strip()) or (isinstance(spec, dict) and not spec):
        raise InputError("domain", "", "empty (leave it out to search every posture)")
    box, _ = parse_box(_every_variable(spec, robot), robot, "domain")
    lo, hi = lo.copy(), hi.copy()
    reachable = np.all(lo <= hi, axis=1)
    angles = {}
    for k, name in enumerate(robot.pose_names):
        if name in robot.angle_names:
            angles[name] = (float(box.lo[k]), float(box.hi[k]))
        else:
            j = system.unknowns.index(name)
            nlo, nhi = np.maximum(lo[:, j], box.lo[k]), np.minimum(hi[:, j], box.hi[k])
            missed = reachable & (nlo > nhi)
            lo[:, j] = np.where(missed, box.lo[k], nlo)
            hi[:, j] = np.where(missed, box.hi[k], nhi)
    return lo, hi, angles


def _every_variable(spec, robot):
    """A domain names only the variables it narrows: the others get the widest range of values
    (positions are then bounded by the leg lengths, angles not filtered)."""
    def wide(name):     # (an angle range of 8 rad holds every angle)
        return (-4, 4) if name in robot.angle_names else (-int(MAX_MAGNITUDE), int(MAX_MAGNITUDE))
    if isinstance(spec, str) and spec.strip():
        named = {part.split("=", 1)[0].strip() for part in spec.split(",") if "=" in part}
        missing = [n for n in robot.pose_names if n not in named]
        return spec + "".join(f",{n}={wide(n)[0]}:{wide(n)[1]}" for n in missing) if named and missing else spec
    if isinstance(spec, dict) and spec:
        return {**{n: wide(n) for n in robot.pose_names}, **spec}
    return spec


def _clusters(lo, hi, limit: int = MAX_UNRESOLVED):
    """Group boxes that touch or overlap (union-find); returns the hull of each group.

    Beyond ``limit`` boxes (a search stopped by its budget) the boxes are
    merged greedily along the first coordinate: fewer, larger clusters, still
    covering every box.
    """
    n = len(lo)
    if n > limit:
        order = np.argsort(lo[:, 0], kind="stable")
        chunks = np.array_split(order, limit)
        return [(lo[c].min(axis=0), hi[c].max(axis=0)) for c in chunks if len(c)]
    parent = np.arange(n)

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i
    touch = np.all((lo[:, None, :] <= hi[None, :, :]) & (lo[None, :, :] <= hi[:, None, :]), axis=-1)
    for i, j in zip(*np.nonzero(np.triu(touch, 1))):
        parent[find(i)] = find(j)
    roots = np.array([find(i) for i in range(n)])
    return [(lo[roots == r].min(axis=0), hi[roots == r].max(axis=0)) for r in np.unique(roots)]


def budget_message(stopped_by) -> str:
    """The note of a search a budget stopped, naming that budget (the command line names its option)."""
    return f"{BUDGETS.get(stopped_by, 'the budget (boxes, seconds or memory)')} {BUDGET_MESSAGE}"
