"""Richardson extrapolation of a number from the coarser members of its grid family.

A family's members differ by one parameter, the spacing h (N/2, N/4 nodes of a uniform grid;
spacings r h, r^2 h of a banded one; :mod:`femadh.discretisation.family`). Where a number
converges like Q(h) = Q* + C h^p, the fine member's error is

    Q* - Q(h) = (Q(h) - Q(r h)) / (r^p - 1)                              (Richardson)

with p assumed (two members: the family's known order) or observed over three members,
p = ln((Q(r h) - Q(r^2 h)) / (Q(h) - Q(r h))) / ln r, admitted within [ORDER, MAX_ORDER].
Where the two differences change sign (a contact edge hopping between nodes: the members
oscillate about the limit), their difference may cancel by chance: the envelope of both at
ENVELOPE_ORDER is taken instead. Where they fall faster than DECAY_ORDER, the finest
difference may be small by chance (the phase of a node-release sawtooth): the coarser one,
scaled down at DECAY_ORDER, bounds it.
"""
import math

#: the order a two-member estimate assumes and the floor of an observed one (conservative:
#: a first-order estimate of a faster sequence over-estimates its error)
ORDER = 1.0
#: order of the envelope of an oscillating convergence (the contact edge moving between
#: nodes, a node at a time): the Fig 3 scene's banded family, spacings 175 -> 15.5 nm, shows
#: local orders from 1.2 to 2.2 around a sign-changing mean; the smaller end is taken
#: (measured for the former validation/adaptive.py study, now validation/accuracy.py)
ENVELOPE_ORDER = 1.5
#: the largest order a monotone sequence of three members may claim: their coarsest member
#: is often pre-asymptotic (Fig 3 banded, 175/87.5/43.75 nm: apparent order 3.4, while the
#: finest pair converges at ~1.3 against a 7.5-nm reference: an order-2 estimate was 0.4x
#: the true error), so the family's envelope order caps it
MAX_ORDER = ENVELOPE_ORDER
#: the fastest a difference of consecutive members may fall before the finest is read as small
#: by chance: second order, the highest a number of a sigma-gap contact shows on the
#: piecewise-linear surface (the Fig 3 family's local orders 1.2-2.2, above), whose contact
#: nodes join and leave one at a time (a sawtooth in the spacing). Without it a monotone
#: triple whose finest difference happens to fall near a sawtooth's zero is extrapolated from
#: that difference alone: effectivity 0.31-0.43 on 3 of 50 spacings of the Fig 3 and slider
#: families' largest adhesion, 0.87 or more with it (validation/results/
#: effectivity_spread.md). Opt-in (``decay_order``): smooth numbers may converge faster, and
#: a member near a node's stiffness is not asymptotic (femadh.runner.estimates.decay_order
#: decides)
DECAY_ORDER = 2.0


def richardson(fine, coarse, ratio, order):
    """Signed estimate Q* - Q(h) of the fine member's error, (Q(h) - Q(r h)) / (r^p - 1).

    Parameters
    ----------
    fine, coarse : float
        The number on the members of spacing h and r h (any unit; the estimate has it).
    ratio : float
        Spacing ratio r > 1 of the two members.
    order : float
        Convergence order p > 0 in the spacing.
    """
    return (fine - coarse) / (ratio**order - 1.0)


def observed_order(fine, coarse, coarser, ratio):
    """Order p the three members show, ln(|Q(rh) - Q(r^2h)| / |Q(h) - Q(rh)|) / ln r, or None
    where they do not converge monotonically (differences of opposite sign, or growing
    towards the fine member)."""
    d1, d2 = fine - coarse, coarse - coarser
    if not (d1 * d2 > 0 and abs(d2) > abs(d1)):
        return None
    return math.log(abs(d2) / abs(d1)) / math.log(ratio)


def observed_order_uneven(fine, coarse, coarser, ratio, ratio2, lo=0.05, hi=8.0):
    """Order p three members of spacings h, r1 h, r1 r2 h show where r1 != r2: the root of
    (Q(r1 h) - Q(r1 r2 h)) / (Q(h) - Q(r1 h)) = r1^p (r2^p - 1) / (r1^p - 1), which grows
    monotonically with p (bisection on [lo, hi]); None where the members do not converge
    monotonically or the root is outside [lo, hi]. With r1 = r2 it is
    :func:`observed_order`'s."""
    d1, d2 = fine - coarse, coarse - coarser
    if not (d1 * d2 > 0):
        return None
    rho = d2 / d1

    def g(p):
        return ratio**p * (ratio2**p - 1.0) / (ratio**p - 1.0) - rho
    if g(lo) > 0 or g(hi) < 0:
        return None
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if g(mid) < 0 else (lo, mid)
    return 0.5 * (lo + hi)


def _finite(x):
    return isinstance(x, float) and math.isfinite(x)


def discretisation(fine, coarse, coarser=None, ratio=2.0, *, order=ORDER, max_order=MAX_ORDER,
                   envelope_order=ENVELOPE_ORDER, ratio2=None, decay_order=None):
    """Signed estimate of each number's discretisation error, Q* - Q(h), from the coarser
    members of its grid family.

    Parameters
    ----------
    fine, coarse, coarser : dict
        {name: value} on the members of spacing h, r h and (optional) r^2 h; names whose
        values are not finite floats on the fine and the coarse member are left out.
    ratio : float
        Spacing ratio r of consecutive members (2 for N, N/2, N/4; sqrt 2 for the runner's
        banded members).
    ratio2 : float, optional
        Spacing ratio of the coarser member to the coarse one where it differs from
        ``ratio`` (members placed by the contact edge,
        :func:`femadh.runner.members.locked_spacings`): the order observed by
        :func:`observed_order_uneven`, the second difference scaled by it.
    order : float
        The order of a two-member estimate and the floor of an observed one.
    max_order, envelope_order : float
        Cap of an observed order; order of the envelope where the members oscillate.
    decay_order : float or None
        The fastest fall of the differences before the coarser one bounds the finest
        (DECAY_ORDER; None, the default: never - where the coarsest member may be outside
        the asymptotic range, e.g. a member that softens near a node's stiffness:
        :func:`femadh.runner.estimates.decay_order` decides).

    Returns
    -------
    dict
        {name: (Q(h) - Q(rh)) / (r^p - 1)} with p observed over three members (clamped to
        [order, max_order]) or ``order`` without the third, the finest difference no smaller
        than the coarser one implies at ``decay_order`` (:func:`_implied`: |Q(rh) - Q(r^2h)|
        / r^2 for even ratios); where the
        members oscillate (or diverge) the envelope
        max(|Q(h) - Q(rh)|, |Q(rh) - Q(r^2h)| / r^p) / (r^p - 1) at p = ``envelope_order``,
        with the sign of the finest difference.
    """
    out = {}
    for k, v in fine.items():
        c = coarse.get(k)
        if not (_finite(v) and _finite(c)):
            continue
        p = order
        cc = (coarser or {}).get(k)
        if _finite(cc) and v != c and cc != c:
            uneven = ratio2 is not None and ratio2 != ratio
            seen = (observed_order_uneven(v, c, cc, ratio, ratio2) if uneven
                    else observed_order(v, c, cc, ratio))
            d1, d2 = v - c, c - cc
            if seen is None:
                # oscillating (a contact edge hopping between nodes): the two differences
                # may cancel by chance; the envelope of both at the family's order
                p = envelope_order
                out[k] = math.copysign(max(abs(d1), abs(d2) * _implied(p, ratio, ratio2)),
                                       d1) / (ratio**p - 1)
                continue
            # monotone convergence: the order it shows, from a finest difference no smaller
            # than the coarser one implies at DECAY_ORDER (a faster fall is chance)
            p = min(max_order, max(order, seen))
            if decay_order is not None:
                d1 = math.copysign(max(abs(d1), abs(d2) * _implied(decay_order, ratio,
                                                                   ratio2)), d1)
            out[k] = d1 / (ratio**p - 1)
            continue
        out[k] = richardson(v, c, ratio, p)
    return out


def _implied(p, ratio, ratio2):
    """Factor taking the coarser difference Q(r1 h) - Q(r1 r2 h) to the finest one it implies
    under Q = Q* + C h^p: (r1^p - 1) / (r1^p (r2^p - 1)); 1 / r^p for even ratios (ratio2
    None or equal)."""
    if ratio2 is None or ratio2 == ratio:
        return ratio**-p
    return (ratio**p - 1) / (ratio**p * (ratio2**p - 1))
