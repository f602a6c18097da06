"""One entry per job for the contact models: the equilibrium at one separation, and a branch
traced through a list of separations. The sigma-gap's contact model picks the solver:
complementarity (and smooth laws without a gap) -> semismooth Newton with stepping
continuation; "hertz-closure" -> the paper's closure (:mod:`femadh.contact.closure`)."""


def _is_closure(problem):
    return problem.contact_model == "hertz-closure"


def solve_state(problem, d, w0, *, tol, max_iter=40, **kw):
    """Equilibrium at separation d (m) from displacements w0 (m); see
    :func:`~femadh.contact.complementarity.solve_complementarity` and
    :func:`~femadh.contact.closure.solve_closure_state` for the keywords."""
    if _is_closure(problem):
        from .closure import solve_closure_state

        return solve_closure_state(problem, d, w0, tol=tol, max_iter=max_iter, **kw)
    from .complementarity import solve_complementarity

    return solve_complementarity(problem, d, w0, tol=tol, max_iter=max_iter, **kw)


def trace(problem, d_values, *, branch, tol, start=None, max_iter=40, on_state=None,
          on_jump=None, progress=None):
    """Follow the stable equilibrium through the separations ``d_values`` (m), folds located
    and landed on; returns a :class:`~femadh.contact.stepping.Sweep`. Raises ConvergenceError
    with the partial sweep attached (``exc.sweep``)."""
    if _is_closure(problem):
        from .closure import trace_closure

        sweep = trace_closure(problem, d_values, branch=branch, tol=tol, start=start,
                              max_iter=max_iter, on_state=on_state, on_jump=on_jump)
        if progress:
            progress(len(d_values) - 1)
        return sweep
    from .stepping import trace_steps

    return trace_steps(problem, d_values, branch=branch, tol=tol, start=start,
                       max_iter=max_iter, on_state=on_state, on_jump=on_jump,
                       progress=progress)
