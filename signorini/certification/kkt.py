"""KKT certificates and active sets: computed here, never by a solver.

For ``min ½uᵀKu − fᵀu  s.t.  Nu ≤ d`` with multipliers ``λ`` every residual is
relative, so that the same threshold means the same thing in any units; the forward
error of λ itself comes from one Newton correction on the active set, and the duality gap from
a factorisation the method already holds when it can (:mod:`signorini.certification.inverse`,
docs/certificate.md). The factorisations on offer to one certificate (the method's, the
problem's cached one) are wrapped once (:class:`Offers`), and each remembers what it solved
(:class:`Remembering`), so that the forward error's back-solve and the gap's, of opposite
right-hand sides, cost one.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace

import numpy as np

from signorini.errors import InputError
from signorini.numerics.active_set import PinnedFactor, selection_dofs
from signorini.certification.curvature import NoMinimum, indefinite
from signorini.certification.inverse import ForwardError, forward_error, pinned_rows, primal_dual_gap
from signorini.problem.contact import ContactProblem, ContactSolution

#: normalised force and gap below which a node counts as touching with zero force
WEAK_TOL = 1e-6
#: forces are judged against max(‖λ‖∞, FORCE_FLOOR · ‖f‖∞): with no contact at all,
#: λ is round-off and relative measures against ‖λ‖∞ alone would be meaningless
FORCE_FLOOR = 1e-5
#: ... unless the candidate carrying the largest force touches the obstacle and that force
#: is above this fraction of ‖f‖∞ (450 ε): then it is a contact force, judged against itself.
#: A load lifted from a prescribed displacement can be 10¹¹ times the contact forces
#: (ν → ½), and against FORCE_FLOOR · ‖f‖∞ every force there would count as zero
FORCE_ROUNDOFF = 1e-13


def inf_norm(x: np.ndarray) -> float:
    """``‖x‖∞`` (0 for an empty x)."""
    return float(np.max(np.abs(x))) if x.size else 0.0


def _positive(x: float) -> float:
    return x if x > 0 else 1.0


def force_scale(problem: ContactProblem, lam: np.ndarray, u: np.ndarray | None = None,
                Nu: np.ndarray | None = None) -> float:
    """``max(‖λ‖∞, FORCE_FLOOR · ‖f‖∞)``: the force against which forces are judged.

    With ``u`` given, ``‖λ‖∞`` alone when the candidate carrying the largest force
    touches (its gap within :data:`WEAK_TOL` of the gap scale) and that force is
    above ``FORCE_ROUNDOFF · ‖f‖∞``: a contact force is never floored by a load
    that does not reach the contact (see :data:`FORCE_ROUNDOFF`). ``Nu``, when the caller
    has it, is ``N u`` (not formed again).
    """
    norm, load = inf_norm(lam), inf_norm(problem.f)
    if u is not None and lam.size and norm > FORCE_ROUNDOFF * load and np.all(np.isfinite(u)):
        Nu = problem.N @ u if Nu is None else Nu
        top = int(np.argmax(np.abs(lam)))
        if lam[top] > 0 and problem.d[top] - Nu[top] <= WEAK_TOL * gap_scale(problem, u, Nu):
            return norm
    return _positive(max(norm, FORCE_FLOOR * load))


def gap_scale(problem: ContactProblem, u: np.ndarray, Nu: np.ndarray | None = None) -> float:
    """Length against which gaps are judged: ``max(‖Nu‖∞, ‖d‖∞, ‖u‖∞)`` (``Nu`` formed
    unless given).

    ``‖u‖∞`` keeps the scale meaningful when the contact nodes neither move
    nor start apart (a block resting on the flat: ``d = 0``, ``Nu = 0``).
    """
    Nu = problem.N @ u if Nu is None else Nu
    return _positive(max(inf_norm(Nu), inf_norm(problem.d), inf_norm(u)))


@dataclass(frozen=True)
class Certificate:
    """Relative KKT residuals of a candidate solution ``(u, λ)``.

    - ``primal``: ``max((Nu − d)⁺) / max(‖Nu‖∞, ‖d‖∞, ‖u‖∞)``
    - ``stationarity``: ``‖Ku − f + Nᵀλ‖∞ / ‖Nᵀλ‖∞``.
      The contact forces set the scale, not ``‖f‖∞ + ‖Nᵀλ‖∞``: the lifted
      load ``f`` sits on dofs next to the prescribed boundary and can be
      hundreds of times the largest nodal contact force, and an imbalance
      that is small against ``f`` can still move λ by much more than the
      tolerance.
    - ``dual_sign``: ``max((−λ)⁺) / ‖λ‖∞``
    - ``complementarity``: ``max |λᵢ (Nu − d)ᵢ| / (‖λ‖∞ · max(‖Nu‖∞, ‖d‖∞, ‖u‖∞))``
    - ``natural``: ``max |min(λ̃ᵢ, g̃ᵢ)|`` with ``λ̃ = λ/‖λ‖∞`` and
      ``g̃ = (d − Nu)/max(‖Nu‖∞, ‖d‖∞, ‖u‖∞)``: the natural (min-map) residual.
      The product form above lets a node keep both a force and a gap of
      ``√residual``; this one is linear in both, so it bounds how far λ and
      the active set can be off (times the conditioning of ``W``).
    - ``duality_gap``: ``|J(u) − D(λ̂)| / max(|J(u)|, |D(λ̂)|)`` with ``J`` the
      energy, ``D`` the dual function and ``λ̂ ≥ 0`` a dual point at least as
      good as ``λ⁺``: a bound on how far the energy of ``u`` is above the
      optimum (see :func:`primal_dual_gap`, which reuses the method's own
      factorisation of K: one back-solve, no factorisation).
    - ``force_error``: ``‖λ − λ*‖∞ / ‖λ‖∞`` with ``(u*, λ*)`` one Newton
      correction of ``(u, λ)`` on the active set A (:func:`active_set`): the
      forward error of the contact force itself, which none of the residuals
      above bounds (they are small against the load, λ can be far smaller).
    - ``displacement_error``: ``‖u − u*‖∞ / ‖u*‖∞``, the same step's.
    - ``force_error_floor``: the force change of a second Newton step: what
      double precision resolves of λ on this system (about ``force_error``
      when the system is too ill-conditioned for the first step to be trusted).
      See :mod:`signorini.certification.inverse` (no factorisation when the method
      holds one; NaN when not estimated).

    Force norms are floored at ``FORCE_FLOOR · ‖f‖∞`` so that a problem with
    no contact (λ = 0 up to round-off) is judged against its loads (not a
    contact force: see :func:`force_scale`).
    Residuals are ``inf`` when ``u`` or ``λ`` is not finite, and the duality gap when K is
    indefinite (:func:`indefinite`: the QP has no minimum).
    """

    primal: float
    stationarity: float
    dual_sign: float
    complementarity: float
    natural: float
    duality_gap: float
    force_error: float = float("nan")
    displacement_error: float = float("nan")
    force_error_floor: float = float("nan")
    #: back-solves the forward error took (not a residual)
    back_solves: int = 0

    def residuals(self) -> dict[str, float]:
        """Every relative residual and error by name (the work count left out)."""
        return {k: v for k, v in asdict(self).items() if k != "back_solves"}

    def worst(self) -> tuple[str, float]:
        """The largest residual and its name."""
        items = {k: v for k, v in self.residuals().items() if not np.isnan(v)}
        return max(items.items(), key=lambda item: item[1])

    as_dict = residuals

    def passed(self, tol: float) -> bool:
        """Every residual and error is finite and at most ``tol``: the answer is certified at
        ``tol`` (what a method's claim of convergence at ``tol`` is held to)."""
        if isinstance(tol, bool) or not isinstance(tol, (int, float, np.floating, np.integer)) \
                or not np.isfinite(tol) or tol <= 0:
            raise InputError(f"Certificate.passed: tol must be a positive number, got {tol!r}")
        return shortfall(self, float(tol)) is None


#: right-hand sides a factorisation offered to the certificate remembers (see :class:`Remembering`)
REMEMBERED_SOLVES = 3


class Remembering:
    """A factorisation offered to one certificate, which remembers what it was asked.

    The forward error's first Newton step and the duality gap can solve the same system with
    opposite right-hand sides (the method's pinned set is the active set, λ zero off it): a
    solve is exactly odd in floating point, so minus a right-hand side already solved gets minus
    its answer, the numbers a second solve gives. Its pinned rows (:func:`pinned_rows`) are
    found once."""

    def __init__(self, problem: ContactProblem, factor):
        self.factor, self.solved = factor, []
        self.pinned = pinned_rows(problem, factor)

    def __getattr__(self, name: str):
        return getattr(self.factor, name)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        rhs = np.asarray(rhs)
        if rhs.ndim == 1:
            for asked, answer in self.solved:
                if np.array_equal(asked, -rhs):
                    return -answer
        answer = self.factor.solve(rhs)
        if rhs.ndim == 1:
            self.solved = [(rhs.copy(), answer.copy())] + self.solved[:REMEMBERED_SOLVES - 1]
        return answer


class Offers:
    """The factorisations on offer to one certificate — the method's, one the certificate made
    (:meth:`add`), then the problem's cached one — each wrapped once in :class:`Remembering`."""

    def __init__(self, problem: ContactProblem, solution: ContactSolution):
        self.problem, self.solution, self.wrapped, self.own = problem, solution, {}, None

    def add(self, factor) -> Remembering:
        """``factor``, made by the certificate itself, on offer from now on."""
        self.own = factor
        return self.wrap(factor)

    def wrap(self, factor) -> Remembering:
        if id(factor) not in self.wrapped:
            self.wrapped[id(factor)] = (factor, Remembering(self.problem, factor))
        return self.wrapped[id(factor)][1]

    def __call__(self) -> list[Remembering]:
        return [self.wrap(f) for f in (self.solution.factor, self.own, self.problem.cached_factor)
                if f is not None]


def certificate(problem: ContactProblem, solution: ContactSolution,
                duality_gap: bool = True) -> Certificate:
    """Relative KKT residuals of ``solution`` for ``problem`` (see :class:`Certificate`).

    ``duality_gap=False`` leaves out what needs K⁻¹: the duality gap and the forward error (NaN
    too when K cannot be factorised; the gap ``inf`` when K is indefinite). The result is kept on
    the solution (for these arrays and values, problem and options): judging then reporting costs one.
    """
    if not isinstance(problem, ContactProblem):
        raise InputError(f"certificate: problem must be a ContactProblem, got {type(problem).__name__}")
    if not isinstance(solution, ContactSolution):
        raise InputError(f"certificate: solution must be a ContactSolution, got "
                         f"{type(solution).__name__} (result.solution for a signorini.solve result)")
    if np.shape(solution.u) != (problem.n,) or np.shape(solution.lam) != (problem.m,):
        raise InputError(f"certificate: solution.u must have {problem.n} entries and solution.lam "
                         f"{problem.m}, got {np.shape(solution.u)} and {np.shape(solution.lam)}")
    key = (id(problem), id(solution.u), id(solution.lam), duality_gap)
    kept = getattr(solution, "_certificate", None)  # and the values: arrays edited are judged again
    arrays = (solution.u, solution.lam)
    if kept is not None and kept[0] == key and all(map(np.array_equal, kept[1], arrays)):
        return kept[2]
    try:
        with np.errstate(all="ignore"):  # an answer beyond double precision: inf residuals say so
            cert = _certificate(problem, solution, duality_gap)
    except np.linalg.LinAlgError as exc:  # K singular or indefinite: no dual, no Newton step
        with np.errstate(all="ignore"):
            cert = _certificate(problem, solution, False)
        if np.isfinite(cert.primal) and (isinstance(exc, NoMinimum) or indefinite(problem.K)):
            cert = replace(cert, duality_gap=float("inf"))
    solution._certificate = (key, tuple(map(np.array, arrays)), cert)
    return cert


def _certificate(problem: ContactProblem, solution: ContactSolution,
                 duality_gap: bool) -> Certificate:
    u, lam = solution.u, solution.lam
    if not (np.all(np.isfinite(u)) and np.all(np.isfinite(lam))):
        inf = float("inf")
        return Certificate(inf, inf, inf, inf, inf, inf, inf, inf, inf)
    violation = problem.N @ u - problem.d
    scale_gap = gap_scale(problem, u)
    NT_lam = problem.N.T @ lam
    lam_norm = force_scale(problem, lam, u)
    floor = lam_norm if lam_norm > inf_norm(lam) else 0.0
    primal = max(float(np.max(violation, initial=0.0)), 0.0) / scale_gap
    Ku = problem.K @ u
    residual = Ku - problem.f + NT_lam
    stationarity = inf_norm(residual) / _positive(max(inf_norm(NT_lam), floor))
    dual_sign = max(float(np.max(-lam, initial=0.0)), 0.0) / lam_norm + 0.0
    complementarity = inf_norm((lam / lam_norm) * (violation / scale_gap))
    natural = inf_norm(np.minimum(lam / lam_norm, -violation / scale_gap))
    gap, forward = float("nan"), ForwardError.unknown()
    if duality_gap:
        offers = Offers(problem, solution)
        if _no_minimum(problem, offers()):  # no minimum: no answer to certify
            raise NoMinimum("K is indefinite")
        forward = _forward(problem, solution, lam_norm, offers, Ku)
        energy = float(0.5 * u @ Ku - problem.f @ u)
        absolute = primal_dual_gap(problem, u, lam, offers(), Ku)
        if not solution.keep_factor:  # used: a kept solution no longer keeps a factorisation alive
            solution.factor = None
        gap = abs(absolute) / _positive(max(abs(energy), abs(energy - absolute)))
    # a residual that overflowed (inf − inf) is NaN, which would read as "not computed": it is inf
    primal, stationarity, dual_sign, complementarity, natural = (
        float("inf") if np.isnan(value) else value
        for value in (primal, stationarity, dual_sign, complementarity, natural))
    return Certificate(primal, stationarity, dual_sign, complementarity, natural, gap,
                       forward.force, forward.displacement, forward.floor, forward.back_solves)


def _no_minimum(problem: ContactProblem, offered: list) -> bool:
    """A K of one's own (no mesh) that is indefinite, unless a plain factorisation of it is on
    offer: one pinned on the active dofs, or of the active set's saddle point, succeeds when the
    negative curvature is pinned. K is factorised plainly (kept on the problem); when that fails,
    :func:`indefinite` says whether the QP has no minimum (a singular K held by its contact has)."""
    if problem.model.mesh is not None or not problem.factorises_for_certificates \
            or any(f.pinned is not None and not f.pinned[0].size for f in offered):
        return False
    try:
        problem.factor()
    except np.linalg.LinAlgError:
        return indefinite(problem.K)
    return False


def _forward(problem: ContactProblem, solution: ContactSolution, scale: float,
             offers: Offers | None = None, Ku: np.ndarray | None = None) -> ForwardError:
    """The forward error on the certificate's active set, by the first usable factorisation.

    The method's (its pinned set checked as for the duality gap), else the problem's cached one,
    else a factorisation of K — the one the duality gap makes anyway — unless the problem does not
    factorise for certificates (:attr:`ContactProblem.factorises_for_certificates`): then the
    gap uses CG and the forward error is not estimated. Where only plain factorisations without
    their Delassus operator are on offer and :data:`PINNED_FROM` or more active rows each bound
    one dof, a model's K is factorised with them pinned instead (the duality gap takes it too).
    """
    offers, active = offers or Offers(problem, solution), active_set(problem, solution)
    offered = [f for f in offers() if f.pinned is not None  # or the saddle point of this system
               or (getattr(f, "on", None) and f.on(problem.K, problem.N, active))]
    plain = all(f.pinned is not None and not f.pinned[0].size  # no pinned dof, no Delassus operator
                and getattr(f, "delassus", None) is None for f in offered)
    many = plain and problem.factorises_for_certificates and active.sum() >= PINNED_FROM \
        and not problem.model.empty  # a K of one's own may be indefinite where it is pinned
    dofs = selection_dofs(problem.N) if many else None
    if dofs is not None:
        offered = [offers.add(PinnedFactor(problem.K, dofs[active]))]
    elif not offered and problem.factorises_for_certificates:
        offered = [offers.wrap(problem.factor())]
    if not offered:
        return ForwardError.unknown()
    return forward_error(problem.K, problem.f, problem.N, problem.d, solution.u, solution.lam,
                         active, offered[0], scale, Ku)


#: from this many active rows, each bounding one dof, a certificate offered no factorisation but
#: a plain one of K factorises K with those dofs pinned (a back-solve a Newton step) instead of
#: bordering the plain one (a back-solve a row): one factorisation costs a few dozen back-solves,
#: and pinning was the faster at every size measured, from 35 rows (docs/certificate.md)
PINNED_FROM = 32


#: what the certificate says when it cannot vouch for the contact force, by the error's name
FORCE_SHORTFALL = {
    "force_error": "the contact force is not certified (force_error {value:.1e} > {accept:.0e}): "
                   "one Newton step on the active set moves λ by {value:.1e} (relative)",
    "displacement_error": "the displacement is not certified (displacement_error {value:.1e} > "
                          "{accept:.0e}): one Newton step on the active set moves u by "
                          "{value:.1e} (relative)",
    "force_error_floor": "the contact force is not certified (force_error_floor {floor:.1e} > "
                         "{accept:.0e}): the system on the active set is too ill-conditioned "
                         "for double precision to resolve λ to {accept:.0e} (one Newton step "
                         "moves it by {force:.1e}, a second one still by {floor:.1e}, relative)",
}


def shortfall(cert: Certificate, accept: float,
              advice: str = "tighten the tolerance or use an exact method (pdas)") -> str | None:
    """Why ``cert`` does not back a claim of convergence at ``accept`` (None when it does).

    What the forward error says about the contact force comes first (see
    :data:`FORCE_SHORTFALL`); then the worst of the other residuals, with ``advice``.
    """
    name, worst = cert.worst()
    if np.isfinite(worst) and worst <= accept:
        return None
    said = []
    errors = {k: v for k, v in cert.residuals().items() if k in FORCE_SHORTFALL and v > accept}
    if errors:
        name = max(errors, key=errors.get)
        floor = cert.force_error_floor
        if name != "displacement_error" and floor > accept and floor >= 0.5 * cert.force_error:
            name = "force_error_floor"  # the first step is noise of the same size: conditioning
        said.append(FORCE_SHORTFALL[name].format(value=errors[name], accept=accept,
                                                 force=cert.force_error, floor=floor))
    if np.isinf(cert.duality_gap) and np.isfinite(cert.primal):
        said.append("K is not positive semidefinite (an eigenvalue is negative): the QP has no "
                    "minimum, and a point meeting its KKT conditions is no answer; give an SPD K")
        return "; ".join(said)
    others = {k: v for k, v in cert.residuals().items() if k not in FORCE_SHORTFALL
              and not np.isnan(v)}
    name = max(others, key=others.get)
    if not np.isfinite(others[name]) or others[name] > accept:
        said.append(f"the method claimed success but the KKT certificate's {name} residual is "
                    f"{others[name]:.1e} > {accept:.0e}" + (f": {advice}" if advice else ""))
    return "; ".join(said)


ACTIVE, WEAK, INACTIVE = "active", "weak", "inactive"


def classify(problem: ContactProblem, solution: ContactSolution,
             weak_tol: float = WEAK_TOL) -> np.ndarray:
    """Label each candidate ``active``, ``inactive`` or ``weak`` (weakly active).

    With ``λ̃ = λ/‖λ‖∞`` and ``g̃ = (d − Nu)⁺ / max(‖Nu‖∞, ‖d‖∞, ‖u‖∞)``: a node is
    weakly active when both are at most ``weak_tol`` (it touches with zero
    force, so its membership of the active set is not determined); otherwise
    it is active when ``λ̃ > g̃`` and inactive when not. For an exact solution
    one of the two is zero; for an inexact one the larger decides. One that penetrates
    by more than ``weak_tol`` is never weak (with no force: inactive).
    """
    u, lam = solution.u, solution.lam
    lam_n = np.maximum(lam, 0.0) / force_scale(problem, lam, u)
    gap = problem.gap(u) / gap_scale(problem, u)
    labels = np.where(lam_n > np.maximum(gap, 0.0), ACTIVE, INACTIVE).astype(object)
    labels[(lam_n <= weak_tol) & (np.abs(gap) <= weak_tol)] = WEAK
    return labels


def active_set(problem: ContactProblem, solution: ContactSolution,
               weak_tol: float = WEAK_TOL) -> np.ndarray:
    """Boolean mask of the (strongly) active candidates."""
    return classify(problem, solution, weak_tol) == ACTIVE


__all__ = ["ACTIVE", "FORCE_FLOOR", "FORCE_ROUNDOFF", "FORCE_SHORTFALL", "INACTIVE", "PINNED_FROM",
           "REMEMBERED_SOLVES", "WEAK", "WEAK_TOL", "Certificate", "Offers", "Remembering",
           "active_set", "certificate", "classify", "force_scale", "gap_scale", "inf_norm", "shortfall"]
