"""Test oracles: exact references that certkin's answers are checked against.

``msolve_fk``: every real forward-kinematics posture of a Gough-Stewart robot,
isolated exactly by msolve; ``robots``: deterministic generators of robots and
leg lengths.  Test helpers only: neither certkin nor proofs imports them.
"""
