"""Paper 1's Hertz closure as the paper states it: one Newton system in the free surface
displacements *and* a continuous contact radius r_c, traced in d through its folds.

Formulation (paper 1 eqs 3-10 and the Fig 2 flowchart)
------------------------------------------------------
Inside the contact, r <= r_c, the gap is clamped to the asperity spacing, h = sigma (eq 8 held
with equality: the flowchart's "w = b - sigma in the contact region"), and the contact pressure
is Hertz's (eq 9), P_el = p_m sqrt(1 - r^2/r_c^2) with p_m = 2 E* r_c/(pi R). Outside, eq (10)
gives the surface:

    w10(r) = P_in D(r, r_c) + P_j [D(r, e_j+1) - D(r, r_c)]
             + sum_{k > j} P(h_k) [D(r, e_k+1) - D(r, e_k)] - W_H(r; r_c)

- D(r, a): displacement at radius r of a unit pressure on the disk r < a (exact, elliptic
  integrals: :func:`femadh.elastic.green.disk_displacement`);
- P_in = P(sigma) + P_LJa: the gap laws at h = sigma plus the eq (20) asperity adhesion, a
  constant attractive pressure acting "over the contact region" r < r_c only;
- e_j <= r_c < e_j+1: the annulus cut by the contact edge; its outer part carries the law at
  its node's gap, P_j = P(h_j) (P(sigma) if that node is inside), so the load is continuous in
  r_c (no jumps when the edge crosses a node or an annulus edge);
- W_H(r; r_c): the Hertz displacement of eq (9) in closed form (Johnson eq 3.42), no
  discretisation of the sqrt edge.

Unknowns: w at the nodes outside r_c (r_k > r_c) and r_c. Equations: eq (10) at those nodes,
F_k = w_k - w10(r_k) = 0, and the edge condition of the flowchart, w(r_c) = b(r_c) - sigma,
evaluated *at r = r_c itself* through the influence of every annulus at that radius,

    G = w10(r_c) - (b(r_c) - sigma) = 0.

One bordered Newton system: the w-block I + coef diag(P'(h)), the r_c column d/dr_c of the
Hertz displacement and of the clamped disk's load (the ring influence dD/da), the edge row d/dw
and d/dr_c of w10(r_c) - b(r_c). A plain backtracking line search on ||(F, G)||_2. Eq (10) is
*not* imposed inside the contact: w = b - sigma there, and its distance from w10 is reported
(``diagnostics["eq10_violation_inside_m"]``). With A = 0 the closure is exactly Hertz:
G = d - sigma + r_c^2/R, so r_c = sqrt(R (sigma - d)).

Stability
---------
The closure has no energy (the Hertz shape is imposed, not derived from a minimum), so
"stable" cannot mean an energy minimum. We call a contact state stable when it lies on the part
of the solution branch connected to the Hertz limit (A -> 0) without crossing a fold, i.e. when
the determinant of the joint Jacobian d(F, G)/d(w_free, r_c) (unknowns and equations in that
order) has the sign it has in the Hertz limit: negative (there the w-block is the identity and
dG/dr_c = -2 r_c/R). The determinant vanishes exactly where the branch x(d) folds (implicit
function theorem), so its sign flips at snap-in and snap-out. Read through the paper's own
iteration: with the w-block regular, det < 0 means the reduced edge residual G(r_c) decreases
through its root, so an under-relaxed r_c update (the flowchart's beta) is drawn back to it. The
sign of the w-block alone, the Schur complement and the branch slope dr_c/dd are kept in
``diagnostics``. A state without contact (r_c = 0) is a true equilibrium of an energy (elastic +
gap laws): it is stable when the energy Hessian is positive definite, as in femadh's solvers.

Landing rule after a fold
-------------------------
At the landing separation the contact branch is scanned in r_c (solving for (w, d) at fixed
r_c, which passes the folds in d), from the departing state's r_c in the direction the contact
moves on the snap (growing on approach, shrinking on retract). The surface lands on the first
*stable* state at that d met by the scan: on approach the stable state with the smallest r_c
above the departing one, on retract the one with the largest r_c below it, or the free
(r_c = 0) state when the scan reaches r_c -> 0 first. With no such state a ConvergenceError
gives the scanned range of d(r_c). A step between the free surface and contact is accepted as
continuous only if the contact branch is stable at its onset (half a node spacing); otherwise
touch-down is itself a fold (eq 20's pull grows with r_c) and the same landing applies.

For an operator with no influence function at arbitrary radii (FE), :class:`InterpolatedInfluence`
interpolates the disk influences between the node/edge radii (first order in the edge position);
the Green operator uses the exact functions (:class:`GreenInfluence`).
"""
from .influence import GreenInfluence, InterpolatedInfluence, influence_for
from .states import solve_closure_state
from .system import ClosureSystem
from .trace import land_closure, trace_closure

__all__ = ["ClosureSystem", "GreenInfluence", "InterpolatedInfluence", "influence_for",
           "solve_closure_state", "trace_closure", "land_closure"]
