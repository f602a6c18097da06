"""Seeded-defect check: does the test suite catch small physics defects?

Each defect is a small edit of the package (a factor, a sign, a term, a safeguard removed),
applied one at a time to a scratch copy of the repository; the default test suite then runs
on that copy (stopping at the first failure): first the tests not marked ``slow``, then, only
if those pass, the slow physics checks. A defect is *caught* if some test fails. The report
names, per defect, the first test that failed and the seconds it took.

    python -m tests.seeded_defects              # all defects, 2 in parallel
    python -m tests.seeded_defects --only lj    # defects whose name contains 'lj'
    python -m tests.seeded_defects --list
    python -m tests.seeded_defects --only est_,guard_ --jobs 1 --report out.md

Writes validation/results/seeded_defects.md. Run it before calling any change to physics
code done: a defect that survives means a physics claim no test asserts. When code moves,
update the file paths and snippets below (an edit that no longer applies is reported as
"not applied", never silently skipped).
"""
import argparse
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
import os
from pathlib import Path
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = Path(__file__).resolve().parents[1]
REPORT = ROOT / "validation" / "results" / "seeded_defects.md"
#: a whole suite run takes ~2-4 min on one loaded core; a defect that makes a solver crawl
#: must not hang us
TIMEOUT_S = 600


@dataclass(frozen=True)
class Defect:
    name: str
    what: str
    path: str
    edits: tuple          # ((old, new), ...): each old must occur exactly once in the file


D = Defect
DEFECTS = [
    # -- elastic operators
    D("green_inside", "disk displacement inside the load +2 %", "femadh/elastic/green.py",
      (("return 4.0 * a / math.pi * special.ellipe", "return 4.08 * a / math.pi * special.ellipe"),)),
    D("green_outside", "disk displacement outside the load: the far-field factor squared",
      "femadh/elastic/green.py",
      (("return a ** 2 / r * outside_factor((a / r) ** 2)",
        "return a ** 2 / r * outside_factor((a / r) ** 2) ** 2"),)),
    D("fe_hoop_strain", "FE weak form: hoop strain u_r/(2r)", "femadh/elastic/fe/weakform.py",
      (("return g[0, 0], g[1, 1], u[0] / r,", "return g[0, 0], g[1, 1], u[0] / (2 * r),"),)),
    D("fe_shear_term", "FE weak form: shear term counted once", "femadh/elastic/fe/weakform.py",
      (("+ 2 * s[3] * ev[3])", "+ s[3] * ev[3])"),)),
    D("fe_far_field", "Boussinesq far field: (1 - nu) instead of 2 (1 - nu)",
      "femadh/elastic/fe/farfield.py",
      (("u_z = c * (zeta**2 / rho**3 + 2 * (1 - nu) / rho)",
        "u_z = c * (zeta**2 / rho**3 + (1 - nu) / rho)"),)),
    D("fe_lame", "Lame lambda with (1 - nu) for (1 + nu)", "femadh/elastic/fe/weakform.py",
      (("return youngs * nu / ((1 + nu) * (1 - 2 * nu)),",
        "return youngs * nu / ((1 - nu) * (1 - 2 * nu)),"),)),
    D("fe_load_quadrature", "FE surface load: FacetBasis quadrature two degrees short",
      "femadh/elastic/fe/weakform.py",
      (("intorder=element.maxdeg + 1 + degree)", "intorder=element.maxdeg - 1 + degree)"),)),
    D("fe_load_radius", "FE surface load without the axisymmetric weight r",
      "femadh/elastic/fe/weakform.py",
      (("return 2 * math.pi * r * p * v[1]", "return 2 * math.pi * p * v[1]"),)),
    D("fe_axis_component", "FE axis: u_z held instead of u_r", "femadh/elastic/fe/operator.py",
      (('self.axis_dofs = np.concatenate([axis.nodal["u^1"], axis.facet["u^1"]])',
        'self.axis_dofs = np.concatenate([axis.nodal["u^2"], axis.facet["u^2"]])'),)),
    D("curve_readout_unrefined", "curve readout: pull-off at the best traced point, not refined",
      "femadh/contact/curve.py",
      (("        pull = max(pull, curve.maximize(i, lambda d, w: force(seg, d, w))[0])",
        "        pull = max(pull, pull)"),)),
    # -- sub-grid integration of the step laws (femadh/contact/subgrid.py)
    D("subgrid_hat_weight", "sub-grid force: the outer node of an element weighted by 1 - t",
      "femadh/contact/subgrid.py",
      (("rows = (s * a, s * t, sp * a * a,", "rows = (s * a, s * a, sp * a * a,"),)),
    D("subgrid_saturated_moment", "sub-grid force: filled element's int t r dt with dr/6",
      "femadh/contact/subgrid.py",
      (("self._m2 = re / 2 + self.dr / 3", "self._m2 = re / 2 + self.dr / 6"),)),
    D("subgrid_one_panel_weights", "sub-grid force: one-panel elements with the two nodes' "
      "weights swapped", "femadh/contact/subgrid.py",
      (("_WS = np.stack([_GW * (1 - _GT), _GW * _GT], axis=1)",
        "_WS = np.stack([_GW * _GT, _GW * (1 - _GT)], axis=1)"),)),
    D("subgrid_energy_cache", "sub-grid energy: the cached value returned for any gap field",
      "femadh/contact/subgrid.py",
      (("if self._last_energy is not None and np.array_equal(self._last_energy[0], h):",
        "if self._last_energy is not None:"),)),
    D("subgrid_offdiagonal", "sub-grid stiffness: the tridiagonal's off-diagonal dropped",
      "femadh/contact/subgrid.py", (("To = kd * d01", "To = 0.0 * d01"),)),
    D("subgrid_outer_annulus", "sub-grid force: the annulus beyond the last node left out",
      "femadh/contact/subgrid.py",
      (("f[-1] += self.outer * P0 * sl", "f[-1] += 0.0 * P0 * sl"),)),
    D("subgrid_panel", "sub-grid quadrature: panels 8 wide in x (not 2)",
      "femadh/contact/subgrid.py", (("PANEL = 2.0", "PANEL = 8.0"),)),
    D("subgrid_window", "sub-grid quadrature: the logistic taken as saturated beyond |x| = 4",
      "femadh/contact/subgrid.py", (("WINDOW = 36.0", "WINDOW = 4.0"),)),
    D("subgrid_energy_closed_form", "sub-grid energy: filled element's int x r dt, dr/3",
      "femadh/contact/subgrid.py",
      (("(x0 * (re + dr / 2) + dx * (re / 2 + dr / 3))[full]",
        "(x0 * (re + dr / 3) + dx * (re / 2 + dr / 3))[full]"),)),
    D("subgrid_row_sums", "tangent: the law's J_II 1 read as its diagonal",
      "femadh/contact/subgrid.py",
      (("    out[:-1] += np.where(mask[1:], np.diagonal(J, 1), 0.0)", "    pass"),)),
    D("subgrid_krylov_apply", "Krylov Newton step: the law Jacobian's lower diagonal applied "
      "with the upper's entries (area-scaled rows: J is not symmetric)",
      "femadh/contact/subgrid.py",
      (("    out[1:] += np.diagonal(B, -1) * v[:-1]", "    out[1:] += np.diagonal(B, 1) * v[:-1]"),)),
    D("subgrid_lu_band", "trailing LU: the sub-grid law's band left out",
      "femadh/contact/linalg.py",
      (("            M += D[m0:, m0:][::-1, ::-1]",
        "            M[np.diag_indices_from(M)] += np.diag(D)[m0:][::-1]"),)),
    D("subgrid_jacobian_scaling", "law Jacobian: T scaled by the column's area, not the row's",
      "femadh/contact/problem.py",
      (("        flat[n::n + 1] = off / a[1:]", "        flat[n::n + 1] = off / a[:-1]"),)),
    D("subgrid_state_pressure", "states carry the collocated pressure of an integrated law",
      "femadh/contact/problem.py",
      (("out[name] = eff.pressure(h) if sub is None else sub.force(h) / self.areas",
        "out[name] = eff.pressure(h)"),)),
    D("subgrid_hessian_band", "energy Hessian: the lower band scaled by the wrong node's area",
      "femadh/contact/problem.py",
      (("            flat[n::n + 1] += a[1:] * np.diagonal(J, -1)",
        "            flat[n::n + 1] += a[:-1] * np.diagonal(J, -1)"),)),

    D("fe_boundary_groups", "FE mesh: each named boundary read with the next group's tag",
      "femadh/elastic/fe/mesh.py",
      (("name = names.get(int(tag), f\"tag_{int(tag)}\")",
        "name = names.get(int(tag) + 1, f\"tag_{int(tag)}\")"),)),
    D("grid_areas", "annulus areas without pi", "femadh/elastic/grid.py",
      (("return math.pi * (e[1:] ** 2 - e[:-1] ** 2)", "return 3.0 * (e[1:] ** 2 - e[:-1] ** 2)"),)),
    D("composite_modulus", "eq 2: second body counted half", "femadh/materials.py",
      (("inv += 1.0 / m2.plane_strain_modulus", "inv += 0.5 / m2.plane_strain_modulus"),)),
    D("plane_strain_modulus", "E/(1 - nu) instead of E/(1 - nu^2)", "femadh/materials.py",
      (("return self.youngs_modulus / (1.0 - self.poisson_ratio**2)",
        "return self.youngs_modulus / (1.0 - self.poisson_ratio)"),)),
    D("sphere_profile", "exact sphere profile replaced by R - sqrt(R^2 - r^2/2)",
      "femadh/indenter.py",
      (("return r * r / (R + np.sqrt(R * R - r * r))",
        "return 0.5 * r * r / (R + np.sqrt(R * R - 0.5 * r * r))"),)),
    # -- pressure laws
    D("lj_pressure", "eq 3: repulsive term 10 % weak", "femadh/laws/lj.py",
      (("return self.hamaker / (6.0 * math.pi * h**3) * (1.0 - s)",
        "return self.hamaker / (6.0 * math.pi * h**3) * (1.0 - 0.9 * s)"),)),
    D("lj_dpressure", "eq 3 derivative: 2.5 for 3 in the repulsive term", "femadh/laws/lj.py",
      (("(1.0 - 3.0 * s)", "(1.0 - 2.5 * s)"),)),
    D("lj_energy", "LJ energy: 0.3 for 1/4 in the repulsive term", "femadh/laws/lj.py",
      (("(1.0 - 0.25 * s)", "(1.0 - 0.3 * s)"),)),
    D("lj_consistent_scale", "whole LJ law (value, derivative, energy) 10 % weak",
      "femadh/laws/lj.py",
      (("self.hamaker / (6.0 * math.pi * h**3)", "self.hamaker / (6.6 * math.pi * h**3)"),
       ("-self.hamaker / (2.0 * math.pi * h**4)", "-self.hamaker / (2.2 * math.pi * h**4)"),
       ("-self.hamaker / (12.0 * math.pi * h**2)", "-self.hamaker / (13.2 * math.pi * h**2)"))),
    D("step_derivative", "smoothed step law: derivative 10 % steep", "femadh/laws/step.py",
      (("return -self._amplitude / self.width * s * (1 - s)",
        "return -1.1 * self._amplitude / self.width * s * (1 - s)"),)),
    D("capillary_one_film", "capillary filled gap counts one adsorbed film, not two",
      "femadh/laws/capillary.py",
      (("return 2 * abs(self.kelvin_radius) + 2 * self.film",
        "return 2 * abs(self.kelvin_radius) + self.film"),)),
    D("capillary_laplace", "Laplace pressure 2 gamma / |r_K|", "femadh/laws/capillary.py",
      (("return self.surface_tension / abs(self.kelvin_radius)",
        "return 2 * self.surface_tension / abs(self.kelvin_radius)"),)),
    D("eq20_asperity_adhesion", "eq 20: pi R_a instead of 2 pi R_a",
      "femadh/laws/asperity.py",
      (("return 2 * math.pi * asperity_radius * surface_energy * density * probability",
        "return math.pi * asperity_radius * surface_energy * density * probability"),)),
    D("gw_elastic", "GW elastic asperity law (eq 23) 10 % strong", "femadh/laws/gw.py",
      (("return 4.0 / 3.0 * self.e_star * s.density * math.sqrt(s.radius)",
        "return 4.4 / 3.0 * self.e_star * s.density * math.sqrt(s.radius)"),)),
    D("gw_adhesion_derivative", "GW adhesion derivative: 2 pi for sqrt(2 pi)",
      "femadh/laws/gw.py",
      (("/ (math.sqrt(2 * math.pi) * s.sigma_a)", "/ (2 * math.pi * s.sigma_a)"),)),
    D("gw_integral", "GW integrals: Gamma(n + 1.1)", "femadh/laws/gw.py",
      (("out = special.gamma(n + 1.0) *", "out = special.gamma(n + 1.1) *"),)),
    # -- contact
    D("active_set_never_releases", "active-set rule never releases a contact node",
      "femadh/contact/complementarity.py",
      (("new_A = (A & (pc + adhesion > 0)) | (I & (h < sigma))",
        "new_A = A | (I & (h < sigma))"),)),
    D("stability_constant", "stability decision replaced by True", "femadh/contact/stability.py",
      (("    return is_positive_definite(H)\n", "    return True\n"),)),
    D("closure_hertz_pressure", "the paper's closure: Hertz contact force 10 % high",
      "femadh/contact/closure/hertz.py",
      (("return 4.0 * e_star / (3.0 * radius) * (g[:-1] - g[1:])",
        "return 4.4 * e_star / (3.0 * radius) * (g[:-1] - g[1:])"),)),
    D("closure_hertz_displacement", "the paper's closure: Hertz displacement inside 10 % high",
      "femadh/contact/closure/hertz.py",
      (("out[i] = (2 * a * a - r[i] ** 2) / (2 * radius)",
        "out[i] = 1.1 * (2 * a * a - r[i] ** 2) / (2 * radius)"),)),
    D("closure_edge_condition", "the paper's closure: edge condition at b - 0.9 sigma",
      "femadh/contact/closure/system.py",
      (("G = w10e - (float(self.sphere.contour(r_c, d)) - self.sigma)",
        "G = w10e - (float(self.sphere.contour(r_c, d)) - 0.9 * self.sigma)"),)),
    D("closure_stability", "the paper's closure: stability sign flipped",
      "femadh/contact/closure/states.py",
      (("st.stable = bool(det_sign < 0)", "st.stable = bool(det_sign > 0)"),)),
    D("fold_resolution", "continuation: folds located to 1/8 of a step, not 1/1024",
      "femadh/contact/stepping.py",
      (("MIN_STEP_FRACTION = 2.0**-10", "MIN_STEP_FRACTION = 2.0**-3"),)),
    D("correction_guard", "continuation: a converged jump accepted as a step",
      "femadh/contact/stepping.py",
      (("MAX_CORRECTION_FRACTION = 0.25", "MAX_CORRECTION_FRACTION = 1e6"),)),
    D("arclength_fold_parity", "arclength: stability not flipped at a fold",
      "femadh/contact/arclength.py",
      (("stable = p.stable != folded", "stable = p.stable"),)),
    D("arclength_tangent_turn", "arclength: no limit on the tangent's turn per step",
      "femadh/contact/arclength.py",
      (("MIN_TANGENT_COS = math.cos(math.radians(30.0))",
        "MIN_TANGENT_COS = math.cos(math.radians(89.0))"),)),
    D("arclength_regrid_near_folds", "arclength: no grid exchange where |dd/ds| < 0.05",
      "femadh/contact/arclength.py",
      (("        if regrid is not None:\n",
        "        if regrid is not None and abs(t[n]) >= REGRID_MIN_TD:\n"),)),
    D("arclength_second_mode", "arclength: every fold flips stability (plain parity)",
      "femadh/contact/arclength.py",
      (("if stable and folded and _negative_modes(problem, fold.w, fold.d) > 0:",
        "if False:"),)),
    D("force_contact", "contact force integrated 10 % low", "femadh/contact/forces.py",
      (("f_el = g.force(state.p_contact)", "f_el = 0.9 * g.force(state.p_contact)"),)),
    D("regime_tail", "regime map: LJ tail beyond the analysis radius dropped "
      "(smooth_sphere.paraboloid_tail_force)",
      "femadh/studies/smooth_sphere.py",
      (("return -2 * math.pi * radius * float(law.energy(d + a * a / (2 * radius)))",
        "return 0.0"),)),
    D("hysteresis_energy", "hysteresis: half the energy released at a jump", "femadh/contact/curve.py",
      (("released += pb(g1).energy(w1, d1) - pb(g2).energy(w2, d1)",
        "released += 0.5 * (pb(g1).energy(w1, d1) - pb(g2).energy(w2, d1))"),)),
    D("regime_estimate", "regime error estimate: Richardson at order 3 for the family's 2",
      "femadh/studies/regime.py",
      (("{k: coarse[k] for k in QUANTITIES}, None, ratio, order=ORDER)",
        "{k: coarse[k] for k in QUANTITIES}, None, ratio, order=3.0)"),)),
    D("regime_trapping_guard", "regime: lattice-trapping guard switched off",
      "femadh/studies/regime.py",
      (('trapped = trapping_message(q["trapping"], TRAPPING_LIMIT)',
        'trapped = trapping_message(q["trapping"], 1e9 * TRAPPING_LIMIT)'),)),
    D("regime_fixed_grip_force", "curve readout: fixed-grip pull-off read at the fold 5 % low",
      "femadh/contact/curve.py",
      (("pull_disp = force(pb(r_folds[-1][2]), *r_folds[-1][:2]) if r_folds else None",
        "pull_disp = 0.95 * force(pb(r_folds[-1][2]), *r_folds[-1][:2]) if r_folds else None"),)),
    # -- references (the judges)
    D("maugis_load", "Maugis-Dugdale load: m atan s for m^2 atan s",
      "femadh/reference/maugis.py",
      (("P = A**3 - lam * A * A * (s + m * m * at)", "P = A**3 - lam * A * A * (s + m * at)"),)),
    D("maugis_fixed_grip", "Maugis-Dugdale fixed grip: load at the vertical tangent 5 % high",
      "femadh/reference/maugis.py", (("return -float(P), float(Dv)",
                                      "return -1.05 * float(P), float(Dv)"),)),
    D("maugis_lambda", "LJ -> Dugdale lambda with sqrt 2 for sqrt 3",
      "femadh/reference/maugis.py",
      (("sigma0_factor = 16.0 / (9.0 * math.sqrt(3.0))",
        "sigma0_factor = 16.0 / (9.0 * math.sqrt(2.0))"),)),
    D("eq17_surface_energy", "eq 17: z0^6 / (3 s^6) for z0^6 / (4 s^6)",
      "femadh/reference/adhesion.py",
      (("(1.0 - z0**6 / (4.0 * spacing**6))", "(1.0 - z0**6 / (3.0 * spacing**6))"),)),
    D("jkr_radius", "JKR contact radius: 3R/(2E*) for 3R/(4E*)",
      "femadh/reference/adhesion.py",
      (("return (3.0 * radius / (4.0 * e_star) * (load + q + math.sqrt(disc)))",
        "return (3.0 * radius / (2.0 * e_star) * (load + q + math.sqrt(disc)))"),)),
    # -- meniscus (paper 2)
    D("kelvin_log10", "Kelvin radius with log10 for ln", "femadh/meniscus/kelvin.py",
      (("(R_GAS * temperature * math.log(p_ratio))", "(R_GAS * temperature * math.log10(p_ratio))"),)),
    D("meniscus_normalisation", "meniscus force normalised by R + h instead of R",
      "femadh/meniscus/solve.py",
      (("F0 = 4 * math.pi * radius * gamma", "F0 = 4 * math.pi * (radius + h) * gamma"),)),
    # -- layered substrates
    D("layered_sphere_compliance", "layered scene: the slider's own compliance dropped",
      "femadh/scene/build.py",
      (("FEOperator.layered(grid, body.disk, body.layers, body.slider, settings,",
        "FEOperator.layered(grid, body.disk, body.layers, None, settings,"),)),
    D("hankel_sphere_twice", "Hankel layered operator: the sphere's compliance counted twice",
      "femadh/judges.py",
      (("+ GreenOperator(grid, sphere.plane_strain_modulus).compliance)",
        "+ 2 * GreenOperator(grid, sphere.plane_strain_modulus).compliance)"),)),
    D("layered_estimate_mesh", "layered estimate: the 'coarser' mesh is the same mesh",
      "femadh/runner/estimates.py",
      (('mesh["growth"] = min(2.0, 2 * fs.growth)', 'mesh["growth"] = fs.growth'),
       ('mesh["surface_fraction"] = min(1.0, 2 * fs.surface_fraction)',
        'mesh["surface_fraction"] = fs.surface_fraction'))),
    D("fe_layer_regions", "layered FE body: the layers' materials assigned one region off",
      "femadh/elastic/fe/operator.py",
      (("            elements = np.flatnonzero(self.region == rid)",
        "            elements = np.flatnonzero(self.region == (rid + 1) % len(self.materials))"),)),
    D("fe_mixed_volumetric", "mixed formulation: volumetric term at half lambda",
      "femadh/elastic/fe/operator.py",
      (("                Kr = Kr + lam * (Bdiv.T @ proj)",
        "                Kr = Kr + 0.5 * lam * (Bdiv.T @ proj)"),)),
    D("vtk_resume_collection", "resumed FE run: the .pvd forgets the states before the resume",
      "femadh/io/writers.py",
      (("self._pvd = self._committed_vtk() if (resume and vtk) else {}", "self._pvd = {}"),)),
    D("fault_reported_converged", "a fault outside the solver leaves the summary 'converged'",
      "femadh/runner/lifecycle.py",
      (("        except BaseException as exc:\n", "        except GeneratorExit as exc:\n"),)),
    D("accuracy_mode_cleans", "accuracy mode claims its folder anew, deleting the outputs",
      "femadh/runner/accuracy.py",
      (('RunFolder(out_dir, scene_id(scene), scene.name, "amend",',
        'RunFolder(out_dir, scene_id(scene), scene.name, "overwrite",'),)),
    # -- stepping: a fold inside one step told by the step's energy
    D("fold_energy_sign", "stepping: the step's energy change counted with the wrong sign",
      "femadh/contact/stepping.py",
      (("released = 0.5 * (g_old + g_new) * dd - (e_new - e_old)",
        "released = 0.5 * (g_old + g_new) * dd + (e_new - e_old)"),)),
    D("fold_energy_share", "stepping: a snap must release the whole step's work",
      "femadh/contact/stepping.py", (("FOLD_ENERGY_SHARE = 0.1", "FOLD_ENERGY_SHARE = 1.0"),)),
    D("fold_total_force_area", "stepping: the total force without the nodes' areas",
      "femadh/contact/stepping.py",
      (("return float(np.sum(problem.S_sym @ state.w))",
        "return float(np.sum(problem.K @ state.w))"),)),
    D("step_budget_edge_ignored", "stepping: a grid step's budget no longer grows with the "
      "contact nodes it moved", "femadh/contact/stepping.py",
      (("            if crawling or solves_here >= MAX_SOLVES_PER_STEP * (1 + jumps_here) \\\n"
        "                    + SOLVES_PER_EDGE_NODE * moved:",
        "            if crawling or solves_here >= MAX_SOLVES_PER_STEP * (1 + jumps_here):"),)),
    D("step_budget_edge_signed", "stepping: the nodes moved counted with their sign (a receding "
      "edge lowers the budget)", "femadh/contact/stepping.py",
      (("moved = abs(int(np.count_nonzero(state.active)) - n_start)",
        "moved = int(np.count_nonzero(state.active)) - n_start"),)),
    D("step_crawl_flag_ignored", "stepping: a crawl of folds no longer stalls its grid step "
      "at once (the cut left to the budget, which the per-edge-node part extends)",
      "femadh/contact/stepping.py",
      (("                crawling = True\n", "                crawling = False\n"),)),
    D("fold_landing_restart", "stepping: a stalled landing no longer restarts on the branch "
      "the corrector found", "femadh/contact/stepping.py",
      (("                    beyond, why = new, \"rejected_energy\"\n",
        "                    why = \"rejected_energy\"\n"),)),
    # -- studies: the operator cache, the done/redo bookkeeping, exit codes, units, workers
    # the operator's key is the content hash of (body, discretisation): femadh/scene/parts
    D("study_key_wrong_part", "a study's operator key of the laws instead of the body (the "
      "modulus, the layers forgotten)", "femadh/studies/executors.py",
      (("return operator_key(*sc.operator_inputs)",
        "return operator_key(sc.laws, sc.discretisation)"),)),
    D("study_key_discretisation_only", "the operator key of the discretisation alone",
      "femadh/scene/build.py",
      (("return content_hash(body, discretisation)", "return content_hash(discretisation)"),)),
    D("operator_reads_the_laws", "the operator's build reads the sigma-gap's contact model "
      "(one more node for the closure), outside its key", "femadh/scene/build.py",
      (("    return operator_from_parts(scene.body, scene.discretisation, progress, grid=grid,",
        "    d = scene.discretisation\n"
        "    if scene.gap is not None and scene.gap.contact_model != 'complementarity':\n"
        "        d = __import__('dataclasses').replace(d, nodes=d.nodes + 1)\n"
        "    return operator_from_parts(scene.body, d, progress, grid=grid,"),)),
    D("study_key_drops_a_field", "the content hash leaves out each part's last field",
      "femadh/scene/parts/frozen.py",
      (("for f in dataclasses.fields(obj)}}", "for f in dataclasses.fields(obj)[:-1]}}"),)),
    D("study_key_float_rounded", "the content hash writes floats to 6 digits",
      "femadh/scene/parts/frozen.py",
      (("            return repr(x)          # JSON has no NaN/inf; as a string they stay "
        "distinct\n        return x\n",
        "            return repr(x)          # JSON has no NaN/inf; as a string they stay "
        "distinct\n        return float(f'{x:.6g}')\n"),)),
    D("scene_tables_writable", "a part's tables (effects, mesh, grid) take new entries",
      "femadh/scene/parts/frozen.py",
      (("    __setitem__ = __delitem__ = _refuse", "    __delitem__ = _refuse"),)),
    D("scene_flat_write_mutates_part", "assigning a flat attribute changes the shared part",
      "femadh/scene/contact.py",
      (("setattr(obj, self.part, dataclasses.replace(part, **{self.name: value}))",
        "object.__setattr__(part, self.name, value)"),)),
    D("scene_id_layout", "the scene's resolved view renames a key (every scene id moves)",
      "femadh/scene/contact.py",
      (('"tolerance_m": self.tolerance', '"tolerance": self.tolerance'),)),
    D("study_point_id_of_base", "a study's points carry the base scene's id",
      "femadh/studies/sweep.py",
      (("points.append(Point(i, changes, sc, scene_id(sc)))",
        "points.append(Point(i, changes, sc, scene_id(scene)))"),)),
    D("study_unfinished_counted_done", "a study re-run reuses interrupted points",
      "femadh/studies/sweep.py",
      (("done = {k: r for k, r in old.items() if finished(r) and k in ids}",
        "done = {k: r for k, r in old.items() if k in ids}"),)),
    D("study_bare_numbers_accepted", "typed values: bare numbers accepted for lengths",
      "femadh/scene/reader.py",
      (("return self.bare_numbers and not any(", "return self.bare_numbers or not any("),)),
    D("study_dead_worker_dropped", "a killed worker's point is never re-queued",
      "femadh/studies/executors.py", (("            queue.append(p)\n", "            pass\n"),)),
    D("study_table_strings", "study.csv keeps the varied values as typed strings",
      "femadh/io/study_table.py",
      (("row.append(si_value(p.changes[k])[0] if dim else p.changes[k])",
        "row.append(p.changes[k])"),)),
    # -- what a user sees: progress width, the FE operator cache, the jump arrows, notes
    D("progress_zero_width", "progress: a terminal reporting 0 columns gets width 0",
      "femadh/io/progress.py",
      (("    return n if n > 0 else fallback", "    return n"),)),
    D("fe_cache_ignores_materials", "FE operator cache key without the materials",
      "femadh/elastic/fe/cache.py",
      (('        "materials": [[repr(float(E)), repr(float(nu))] for E, nu in op.materials],\n',
        ""),)),
    D("fe_cache_ignores_mesh_bytes", "FE operator cache keyed by the mesh settings, not its file",
      "femadh/elastic/fe/cache.py",
      (('        "mesh": _file_hash(op._mesh_path),', '        "mesh": op.spec.key(),'),)),
    D("jump_arrow_direction", "the figure's jump arrows point the same way on both branches",
      "femadh/io/plots.py",
      (('    sign = -1.0 if branch == "approach" else 1.0', "    sign = 1.0"),)),
    # -- runs: signals at safe points, checked resume, checkpoints, the lock
    D("interrupt_no_safe_point_in_newton", "complementarity Newton never checks for a signal",
      "femadh/contact/complementarity.py",
      (("        safe_point()\n        I = ~A", "        I = ~A"),)),
    D("resume_checksum_ignored", "resume: a row whose checksum does not match is accepted",
      "femadh/io/resume_check.py", (('        return "checksum"', "        pass"),)),
    D("resume_no_checkpoint", "a sweep stopped by a signal saves no checkpoint",
      "femadh/runner/contact.py",
      (("        life.on_stop = lambda: save_checkpoint(folder, sink)",
        "        life.on_stop = lambda: None"),)),
    D("resume_ignores_fields", "resume point not cut back to what fields.csv holds",
      "femadh/io/resume_check.py",
      (("    keep = min(k, ok_f, ok_d, ok_j)", "    keep = min(k, ok_d, ok_j)"),)),
    D("interrupt_immediate_ignored", "a signal during the figures waits for them to finish",
      "femadh/interrupt.py",
      (("    if _pending or _immediate[0]:", "    if _pending:"),)),
    D("resume_drops_jumps", "a resumed sweep forgets the jumps before the resume point",
      "femadh/runner/checkpoint.py",
      (('"jumps": kept_jumps(folder.path, rows[:k]), "rows": rows[:k]}',
        '"jumps": 0, "rows": rows[:k]}'),)),
    D("lock_on_removed_file", "a lock taken on a removed lock file counts as held",
      "femadh/io/run_folder.py",
      (("            if same:\n                break", "            if True:\n                break"),)),
    D("atomic_owner_only", "atomically written files stay owner-only (0600)",
      "femadh/io/atomic.py", (("    os.chmod(tmp, _MODE)\n", ""),)),
    D("meniscus_contact_geometry", "meniscus in contact at D = -h instead of -2h",
      "femadh/meniscus/solve.py",
      (("geo = Geometry(Re / r_k, (s - 2 * h) / Re)", "geo = Geometry(Re / r_k, (s - h) / Re)"),)),
    D("meniscus_first_integral", "first integral without the 1/2", "femadh/meniscus/geometry.py",
      (("return r * math.sin(psi) - 0.5 * kappa * r * r", "return r * math.sin(psi) - kappa * r * r"),)),
    D("meniscus_fe_curvature", "FE meridian: azimuthal curvature 10 % weak",
      "femadh/meniscus/profile_fe.py",
      (("f_psi = geo.kappa - sp / rq", "f_psi = geo.kappa - 0.9 * sp / rq"),)),
    D("circular_force", "circular approximation: kappa sin^2 instead of kappa sin^2 / 2",
      "femadh/meniscus/circular.py",
      (("return s2 - 0.5 * geo.kappa * s2", "return s2 - geo.kappa * s2"),)),
    D("gab_isotherm", "GAB isotherm: (1 + c k x) for (1 - k x + c k x)",
      "femadh/meniscus/isotherms.py",
      (("return self.monolayer * self.c * kx / ((1 - kx) * (1 - kx + self.c * kx))",
        "return self.monolayer * self.c * kx / ((1 - kx) * (1 + self.c * kx))"),)),
    # -- the adaptive discretisation
    D("richardson_ratio", "Richardson on banded members: 2^p - 1 whatever the spacing ratio",
      "femadh/estimate/richardson.py",
      (("    return (fine - coarse) / (ratio**order - 1.0)",
        "    return (fine - coarse) / (2.0**order - 1.0)"),)),
    D("envelope_dropped", "oscillating members: the finest difference alone (may cancel)",
      "femadh/estimate/richardson.py",
      (("                out[k] = math.copysign(max(abs(d1), abs(d2) * _implied(p, ratio, "
        "ratio2)),", "                out[k] = math.copysign(max(abs(d1), 0.0 * _implied(p, "
        "ratio, ratio2)),"),)),
    D("member_spacing", "estimate members: both at r h instead of r h and r^2 h",
      "femadh/runner/estimates.py", (('h = g["spacing"] * r**k', 'h = g["spacing"] * r'),)),
    D("tail_share", "analysis radius: the tail allowed the whole target, not its share",
      "femadh/discretisation/plan.py",
      (("<= TAIL_SHARE * target * scale", "<= target * scale"),)),
    D("trap_cap_off", "adaptive grid: the trapping-safe spacing never applied",
      "femadh/runner/adaptive.py", (("        if spacing <= safe:", "        if True:"),)),
    D("band_never_widens", "adaptive grid: a contact that left the band is not noticed",
      "femadh/runner/adaptive.py",
      (("if edge > BAND_FILL * family.band and", "if edge > 10 * family.band and"),)),
    D("failure_refuses", "adaptive grid: a failed landing ends the run instead of refining",
      "femadh/runner/adaptive.py",
      (("            ahead[\"next\"] = (family, 0.5 * h)", "            ahead[\"next\"] = None"),)),
    D("feature_gap_fraction", "feature gap: |P'| threshold 1e-3 instead of FEATURE_FRACTION",
      "femadh/discretisation/plan.py",
      (("stiff >= FEATURE_FRACTION * top", "stiff >= 1e-3 * top"),)),
    D("tail_refines_h", "adaptive grid: a tail the capped disk cannot hold refines the spacing "
      "in vain", "femadh/runner/adaptive.py",
      (("    if tail_e > SAFETY * target:", "    if False:"),)),
    # -- the instrument in series with the contact
    D("instrument_z_sign", "instrument: drive z = d - F/k (the spring's force reversed)",
      "femadh/instrument/readout.py",
      (("z_of = lambda q: q.d + q.F / k", "z_of = lambda q: q.d - q.F / k"),)),
    D("instrument_no_tail", "instrument: the force beyond the analysis radius dropped",
      "femadh/instrument/readout.py",
      (("F_ex, F = F, F + tail(d)", "F_ex, F = F, F + 0 * tail(d)"),)),
    D("instrument_walks_through_turn", "instrument: held past z's turning point (stability "
      "dF/dd > -k ignored)", "femadh/instrument/readout.py",
      (("while 0 <= nxt < len(p.d) and s * (z[nxt] - z[i]) > 0 and",
        "while 0 <= nxt < len(p.d) and True and"),)),
    D("instrument_landing_force", "instrument: the landing's force taken at the state before "
      "it, not interpolated", "femadh/instrument/readout.py",
      (("best = (gap, q, int(a), dL, q.F[a] + t * (q.F[a + 1] - q.F[a]))",
        "best = (gap, q, int(a), dL, q.F[a])"),)),
    D("instrument_lands_on_its_branch", "instrument: a landing allowed on another trace of "
      "the branch it just left", "femadh/instrument/readout.py",
      (("abs(np.interp(dJ, q.d, q.F) - FJ) <= step_F:", "abs(np.interp(dJ, q.d, q.F) - FJ) "
        "<= -1.0:"),)),
    D("mems_verdict_reversed", "MEMS verdict: stuck when the jump-out comes before the rest "
      "gap", "femadh/runner/instrument.py",
      (("    if folds and i <= folds[-1]:", "    if folds and i > folds[-1]:"),)),
    D("instrument_fresh_duplicates", "instrument: fresh states solved where the branch has "
      "one already (read as a turn of z)", "femadh/runner/instrument.py",
      (("if np.any(np.abs(have - d) <= 1e-6 * (hi - lo)):", "if False:"),)),
    D("instrument_pull_off_exact", "instrument: the pull-off from the peak search claimed "
      "exact (resolution 0)", "femadh/runner/instrument.py",
      (("ins[\"resolution\"][\"pull_off_N\"] = max(abs(F - sampled),",
        "ins[\"resolution\"][\"pull_off_N\"] = 0 * max(abs(F - sampled),"),)),
    D("bridge_factor", "fixed-fixed bridge: 12 E w t^3 / L^3 instead of 16",
      "femadh/instrument/spring.py",
      (("return 16.0 * youngs_modulus", "return 12.0 * youngs_modulus"),)),
    D("jkr_spring_sign", "JKR with a spring: instability at dP/dD = +k",
      "femadh/reference/maugis.py", (("return dP + k_tilde * dD", "return dP - k_tilde * dD"),)),
    # -- sigma-gap continuation
    D("sigma_arc_orientation", "sigma-gap arclength: a new contact node's piece followed "
      "against the complementarity (its pressure falling)", "femadh/contact/sigma_arclength.py",
      (("        if grow < 0:\n            t2 = -t2", "        if grow > 0:\n            t2 = -t2"),)),
    D("sigma_arc_jacobian_d", "sigma-gap arclength: dF/dd of the free nodes with +P' for -P'",
      "femadh/contact/sigma_arclength.py",
      (("J[:, -1] = self._KIA1 - D", "J[:, -1] = self._KIA1 + D"),)),
    D("sigma_arc_multiplier", "sigma-gap arclength: contact pressure without the LJ pressure "
      "at sigma (lambda = P_LJa - (K w)_j)", "femadh/contact/sigma_arclength.py",
      (("self.lam0 = float(problem.pressure(np.array([self.sigma]))[0]) + adh",
        "self.lam0 = adh"),)),
    # -- force curves and fits
    D("fc_afm_sign", "measured-curve model: F_AFM = +F_ex (the AFM sign not reversed)",
      "femadh/fitting/model.py",
      (('x, f = np.asarray(cols["d_m"], float), -np.asarray(cols["F_ex_N"], float)',
        'x, f = np.asarray(cols["d_m"], float), np.asarray(cols["F_ex_N"], float)'),)),
    D("fit_stderr_no_s2", "fit: covariance (J^T J)^-1 without s^2 = RSS/(n - p)",
      "femadh/fitting/lsq.py",
      (("cov_n = s2 * np.linalg.inv(A)", "cov_n = np.linalg.inv(A)"),)),
    D("fit_offset_frozen", "fit: the contact-point offset not fitted (the residual keeps the "
      "starting offset)", "femadh/fitting/lsq.py",
      (("r = sim.force_at(curve.z, curve.branch, x[q] * OFFSET_SCALE) - curve.force",
        "r = sim.force_at(curve.z, curve.branch, x0[q] * OFFSET_SCALE) - curve.force"),)),
    # -- topography statistics
    D("topo_mccool_radius", "McCool summit radius from the sum of the principal curvatures "
      "(0.375 -> 0.1875)", "femadh/roughness/moments.py",
      (("RADIUS_COEFF = 0.375", "RADIUS_COEFF = 0.1875"),)),
    D("topo_moments_x_only", "profile moments of a map from its x profiles only",
      "femadh/roughness/moments.py",
      (("m = [(a + b) / 2 for a, b in zip(mx, my)]", "m = mx"),)),
    D("topo_composite_zm", "Table 2 composite: z_m in quadrature instead of summed",
      "femadh/roughness/composite.py",
      (("z_m=s1.z_m + s2.z_m,", "z_m=math.hypot(s1.z_m, s2.z_m),"),)),
    D("topo_cutoff_sharp", "cutoff moments: a sharp abs(q) <= q_c mask, no lattice-cell "
      "weight",
      "femadh/roughness/moments.py",
      (("return np.clip((q_c - np.abs(q)) / dq + 0.5, 0.0, 1.0)",
        "return (np.abs(q) <= q_c).astype(float)"),)),
    # -- the error estimate part by part, its family ratios and its guards (issue 24)
    D("est_richardson_no_minus_one", "Richardson: (Q_h - Q_rh) / r^p, without the - 1",
      "femadh/estimate/richardson.py",
      (("    return (fine - coarse) / (ratio**order - 1.0)",
        "    return (fine - coarse) / ratio**order"),)),
    D("est_richardson_sign", "Richardson: the signed estimate Q_rh - Q_h (the wrong side)",
      "femadh/estimate/richardson.py",
      (("    return (fine - coarse) / (ratio**order - 1.0)",
        "    return (coarse - fine) / (ratio**order - 1.0)"),)),
    D("est_order_log_base", "observed order: log of the difference ratio over log 2 whatever "
      "the spacing ratio", "femadh/estimate/richardson.py",
      (("math.log(abs(d2) / abs(d1)) / math.log(ratio)",
        "math.log(abs(d2) / abs(d1)) / math.log(2.0)"),)),
    D("est_order_cap_off", "observed order not capped at MAX_ORDER (a pre-asymptotic member "
      "claims order 3)", "femadh/estimate/richardson.py",
      (("p = min(max_order, max(order, seen))", "p = min(9.0, max(order, seen))"),)),
    D("est_order_floor", "the floor order (and the two-level order) 1.5 instead of 1",
      "femadh/estimate/richardson.py", (("\nORDER = 1.0\n", "\nORDER = 1.5\n"),)),
    D("est_diverging_as_monotone", "a diverging one-signed sequence extrapolated as if it "
      "converged", "femadh/estimate/richardson.py",
      (("if not (d1 * d2 > 0 and abs(d2) > abs(d1)):", "if not d1 * d2 > 0:"),)),
    D("est_grid_part_half", "the grid part halved on its way into the breakdown",
      "femadh/runner/estimates.py",
      (('decay_order=decay).items():\n                parts.setdefault(k, {})["grid"] = v\n'
        '        if locked',
        'decay_order=decay).items():\n                parts.setdefault(k, {})["grid"] = '
        '0.5 * v\n        if locked'),)),
    D("est_total_signed", "total: |sum of the signed parts| (grid and tail cancel)",
      "femadh/runner/estimates.py",
      (('comp["total"] = float(sum(abs(v) for v in comp.values()))',
        'comp["total"] = float(abs(sum(comp.values())))'),)),
    D("est_total_drops_tail", "total: the tail part left out",
      "femadh/runner/estimates.py",
      (('comp["total"] = float(sum(abs(v) for v in comp.values()))',
        'comp["total"] = float(sum(abs(v) for n, v in comp.items() if n != "tail"))'),)),
    D("est_tail_at_deepest", "tail part of the largest adhesion taken at the deepest d",
      "femadh/runner/estimates.py",
      (('parts.setdefault(name, {})["tail"] = tail_force(problem, hl[d_key])',
        'parts.setdefault(name, {})["tail"] = tail_force(problem, hl["d_deepest_m"])'),)),
    D("est_tolerance_area", "tolerance part over the largest annulus, not the disk",
      "femadh/runner/estimates.py",
      (("float(problem.areas.sum() * scene.tolerance",
        "float(problem.areas.max() * scene.tolerance"),)),
    D("est_tolerance_gap", "tolerance part at twice the contact gap's stiffness point",
      "femadh/runner/estimates.py",
      (("np.full(1, _contact_gap(problem))", "np.full(1, 2 * _contact_gap(problem))"),)),
    D("est_peak_bracket", "peak search to 1e-3 of its bracket (resolution 10x coarser)",
      "femadh/runner/peak.py",
      (("state_forces(problem, best)[2]\n    lo, hi = sorted((prev.d, nxt.d))\n"
        "    xatol = PEAK_XTOL_FRACTION * (hi - lo)",
        "state_forces(problem, best)[2]\n    lo, hi = sorted((prev.d, nxt.d))\n"
        "    xatol = 1e-3 * (hi - lo)"),)),
    D("est_uniform_members", "uniform family: members N/2 and N/3 at the ratio 2",
      "femadh/runner/estimates.py",
      (("    return n // 2, n // 4\n", "    return n // 2, n // 3\n"),)),
    D("est_uniform_ratio", "uniform family: Richardson ratio 1.5 for members at 2",
      "femadh/runner/estimates.py",
      (("            return 2.0, out, None", "            return 1.5, out, None"),)),
    D("est_mesh_ratio_sqrt", "layered mesh size ratio n_f/n_c (off by a square root)",
      "femadh/runner/estimates.py",
      (("else math.sqrt(n_f / n_c)", "else n_f / n_c"),)),
    D("est_mesh_order", "layered mesh part: Richardson at order 2 for the P2 body's 3",
      "femadh/runner/estimates.py",
      (("discretisation(hl, g.headline, ratio=ratio, order=FE_ORDER)",
        "discretisation(hl, g.headline, ratio=ratio, order=2)"),)),
    D("est_mesh_green_sign", "homogeneous FE mesh part signed FE - Green",
      "femadh/runner/estimates.py",
      (("else fe_against_green(hl, g.headline))",
        "else fe_against_green(g.headline, hl))"),)),
    D("guard_edge_fraction", "contact guard: the contact may pass the analysis radius (1.2 a)",
      "femadh/estimate/guards.py", (("EDGE_FRACTION = 0.9", "EDGE_FRACTION = 1.2"),)),
    D("guard_edge_node", "contact guard: the outermost node in contact not refused",
      "femadh/estimate/guards.py",
      (("if state.r_c > EDGE_FRACTION * a or (state.active.size and state.active[-1]):",
        "if state.r_c > EDGE_FRACTION * a:"),)),
    D("guard_trapping_limit", "trapping guard at 1.5x a node's stiffness",
      "femadh/estimate/guards.py", (("TRAPPING_LIMIT = 1.0", "TRAPPING_LIMIT = 1.5"),)),
    D("guard_dmt_margin", "bounds guard: twice the estimated error allowed",
      "femadh/estimate/guards.py",
      (("or value - error > upper * (1 + math.copysign(rel, upper)))",
        "or value - 2 * error > upper * (1 + math.copysign(rel, upper)))"),)),
    D("plan_safe_spacing", "trapping-safe spacing for the r h member, not the coarsest r^2 h",
      "femadh/discretisation/plan.py",
      (("return trapping_spacing(problem, TRAP_SAFE / MIN_MEMBER_RATIO**2)",
        "return trapping_spacing(problem, TRAP_SAFE / MIN_MEMBER_RATIO)"),)),
    # -- a meniscus edge just above the sigma-gap floor: its cohesive zone in the plan
    D("step_edge_dropped", "plan: a sub-grid step's edge softening left out of the trapping "
      "ratio (the planned spacing from LJ alone)", "femadh/discretisation/plan.py",
      (("soft = max(soft, law.edge_softening(floor)",
        "soft = max(soft, 0.0 * law.edge_softening(floor)"),)),
    D("step_edge_reach", "step edge softening: the secant over h_c + 2w, not from the floor",
      "femadh/laws/step.py",
      (("reach = self._center + 2.0 * self.width - floor",
        "reach = self._center + 2.0 * self.width"),)),
    D("step_edge_pressure", "step edge softening: the pressure at the edge (P0/2), not at the "
      "floor", "femadh/laws/step.py",
      (("float(self.pressure(np.array([floor]))[0]) / reach",
        "float(self.pressure(np.array([self._center]))[0]) / reach"),)),
    D("step_safe_loose", "plan: the fine member's step ratio allowed 0.9 (not 0.3)",
      "femadh/discretisation/plan.py", (("STEP_SAFE = 0.3", "STEP_SAFE = 0.9"),)),
    D("plan_member_ratio", "banded family: members at 2^(1/4) h (Richardson divides by ~0.2)",
      "femadh/discretisation/plan.py",
      (("MIN_MEMBER_RATIO = 2.0**0.5", "MIN_MEMBER_RATIO = 2.0**0.25"),)),
    D("plan_tail_cap", "tail planning: the analysis radius may grow past the sphere",
      "femadh/discretisation/plan.py", (("2 * a > cap:", "2 * a > 1e9 * cap:"),)),
    D("accuracy_tail_threshold", "accuracy mode: the disk grows only once the tail is 3x the "
      "target", "femadh/runner/accuracy.py",
      (("if tail > target / 3:", "if tail > 3 * target:"),)),
    # -- the error machinery's one home (femadh.estimate; issue 21)
    D("refine_unresolved_met", "refine loop: an attempt a guard refused counts as met",
      "femadh/estimate/refine.py",
      (("        if why is None and error <= target:", "        if error <= target:"),)),
    D("refine_node_budget", "refine loop: the node budget checked at twice its value",
      "femadh/estimate/refine.py",
      (("if nodes(setting, result, nxt) > budget.max_nodes:",
        "if nodes(setting, result, nxt) > 2 * budget.max_nodes:"),)),
    D("worst_floor_dropped", "worst quantity: the floors (hysteresis) ignored",
      "femadh/estimate/refine.py",
      (("ref = max(abs(v), (floors or {}).get(k, 0.0))", "ref = abs(v)"),)),
    D("bounds_lower_side", "bounds guard: the error counted against the lower bound",
      "femadh/estimate/guards.py",
      (("return (value + error < lower * (1 - math.copysign(rel, lower))",
        "return (value - error < lower * (1 - math.copysign(rel, lower))"),)),
    D("regime_judged_cap_off", "regime: the lattice cap dropped though the fixed-grip "
      "pull-off is judged", "femadh/studies/regime.py",
      (('            elif "pull_off_displacement" in judged:',
        '            elif False:'),)),
    D("regime_judged_ignored", "regime: the accuracy judged on every quantity whatever is asked",
      "femadh/studies/regime.py",
      (('fine["errors"], fine["worst"] = errors, _worst(fine, errors, judged)',
        'fine["errors"], fine["worst"] = errors, _worst(fine, errors)'),)),
    # -- the regime map's contact branch traced in its edge radius (edge-following grid)
    D("edge_scaled_compliance", "edge branch: the scaled grid keeps the reference compliance "
      "(C not scaled by lambda)", "femadh/contact/edge_branch.py",
      (("self.compliance = lam * base.compliance", "self.compliance = base.compliance"),)),
    D("edge_slope_moving_nodes", "edge branch: dd/dc without the nodes' motion (shape "
      "derivative dropped)", "femadh/contact/edge_branch.py",
      (("dshape = self.sphere.slope(r) * r / st.c", "dshape = 0.0 * r"),)),
    D("edge_hysteresis_tail", "edge trace: the approach work without the tail beyond the "
      "analysis radius", "femadh/studies/smooth_sphere.py",
      (("+ tail_energy_change(law, R, pba.grid.radius, fin.d, d_out))", ")"),)),
    D("edge_gauss_jacobian", "edge trace: the contact branch's work without the Gauss "
      "interval's half-length", "femadh/studies/smooth_sphere.py",
      (("contact_work += wi * half_c * F(st) * branch.slope(st)",
        "contact_work += wi * F(st) * branch.slope(st)"),)),
    D("edge_grid_band", "edge grid: coarsening from the edge node (no uniform band)",
      "femadh/contact/edge_branch.py",
      (("return spacing * (1.0 + max(x - half, 0.0) / grading)",
        "return spacing * (1.0 + x / grading)"),)),
    D("edge_coarse_ratio", "regime: the coarser member's spacing ratio reported as 1.5 "
      "whatever it was", "femadh/studies/regime.py",
      (("            return (solve_point(mu, radius, law, res.coarser(ratio), tol, None, fixed_grip),\n"
        "                    ratio)",
        "            return (solve_point(mu, radius, law, res.coarser(ratio), tol, None, fixed_grip),\n"
        "                    1.5)"),)),
    D("edge_radius_margin", "edge trace: the reference grid's radius equal to the point's "
      "(the grid shrinks below it at the fold)", "femadh/studies/smooth_sphere.py",
      (("EDGE_RADIUS_MARGIN = 3.0", "EDGE_RADIUS_MARGIN = 1.0"),)),
    # -- the peer problem's cuts: approach branch in its centre gap, parabolic maximum,
    #    the pull-off's grading
    D("centre_gap_slope_rhs", "centre-gap branch: dd/dg with the unit load on node 0's "
      "equation, not the pinned gap's", "femadh/contact/edge_branch.py",
      (("        rhs[self.n] = 1.0\n", "        rhs[0] = 1.0\n"),)),
    D("centre_gap_fold_state", "edge trace: the jump-in taken at the traced state before the "
      "fold, not located", "femadh/studies/smooth_sphere.py",
      (("    fin = atr.fold(arun[-1].c, arun[-3].c)\n", "    fin = arun[-2]\n"),)),
    D("approach_at_separation_jacobian", "centre-gap branch: the fixed-separation Newton's "
      "Jacobian with the law's stiffness subtracted", "femadh/contact/edge_branch.py",
      (("J.ravel()[np.arange(n) * (n + 1)] += self._dpressure(h)",
        "J.ravel()[np.arange(n) * (n + 1)] -= self._dpressure(h)"),)),
    D("parabola_stop_early", "edge branch: the maximum search stops once its vertex is "
      "within 300x MAX_XTOL of the best state", "femadh/contact/edge_branch.py",
      (("            if abs(x - b) <= tol:       # the vertex is on the best state",
        "            if abs(x - b) <= 300 * tol:       # the vertex is on the best state"),)),
    D("parabola_bracket", "edge branch: a better state dropped from the maximum's bracket",
      "femadh/contact/edge_branch.py",
      (("            if fx > fb:     # the new best", "            if fx < fb:     # the new best"),)),
    D("peer_grading_contact", "regime: the pull-off's grading applied to the approach grid "
      "only", "femadh/studies/regime.py",
      (("res = replace(res, grading=g, edge_grading=g)", "res = replace(res, grading=g)"),)),
    # -- the peer problem under 20 ms: factorisations kept across states, the states'
    #    forces from their own pressures, the residual tied to the request, the predictor
    D("peer_predictor_weight", "edge branch: the march's Lagrange predictor with a wrong "
      "weight", "femadh/contact/edge_branch.py",
      (("                li *= (c - cj) / (cs[i] - cj)",
        "                li *= (c - cj) / (cs[i] + cj)"),)),
    D("peer_force_area_scaling", "edge branch: a state's grid force with the annuli scaled "
      "by lam, not lam^2", "femadh/contact/edge_branch.py",
      (("return st.lam * st.lam * float(self._areas0 @ st.P)",
        "return st.lam * float(self._areas0 @ st.P)"),)),
    D("peer_softening_scaling", "edge branch: a state's node softening against the "
      "reference grid's stiffness (K0, not K0 / lam)", "femadh/contact/edge_branch.py",
      (("return float((-self._dpressure(st.h) * st.lam / self._kdiag0).max())",
        "return float((-self._dpressure(st.h) / self._kdiag0).max())"),)),
    D("peer_reuse_span", "edge branch: the last factorisation dropped for a nearby state and "
      "kept for a far one", "femadh/contact/edge_branch.py",
      (("if self._lu is not None and abs(c - self._lu_at) > REUSE_SPAN * abs(c):",
        "if self._lu is not None and abs(c - self._lu_at) < REUSE_SPAN * abs(c):"),)),
    D("peer_scaled_jacobian", "edge branch: the scaled Jacobian's law stiffness not scaled "
      "by lam", "femadh/contact/edge_branch.py",
      (("        lD = lam * D\n", "        lD = D\n"),)),
    D("peer_tolerance_request", "regime: the states' residual not scaled by the accuracy "
      "request", "femadh/studies/regime.py",
      (("return max(TOL, TOL_PER_ACCURACY * accuracy * z0)",
        "return max(TOL, TOL_PER_ACCURACY * z0)"),)),
    D("peer_approach_tail", "edge trace: an approach state's force without the tail beyond "
      "the analysis radius", "femadh/studies/smooth_sphere.py",
      (("st.force = app.grid.force(st.P) + paraboloid_tail_force(law, R, st.d, app.grid.radius)",
        "st.force = app.grid.force(st.P)"),)),
    D("peer_md_once", "regime: the point's Maugis-Dugdale fixed grip solved at the wrong mu",
      "femadh/studies/regime.py",
      (("    fg = md_fixed_grip(mu)          # (once", "    fg = md_fixed_grip(2 * mu)          # (once"),)),
    # -- fold accounting
    D("closure_jump_resolution", "closure: a fold's resolution reported as the grid step",
      "femadh/contact/closure/trace.py",
      (("sweep.jumps.append(Jump(branch, state.d, d_try, abs(d_try - state.d), state, landed))",
        "sweep.jumps.append(Jump(branch, state.d, d_try, abs(grid_step), state, landed))"),)),
    D("arclength_unstable_folds_dropped", "arclength: only folds onto a stable piece recorded",
      "femadh/contact/arclength.py",
      (("        if folded:\n            fold.seg = tr.seg\n            curve.folds.append(fold)",
        "        if folded and stable:\n            fold.seg = tr.seg\n"
        "            curve.folds.append(fold)"),)),
    # -- meniscus film geometry
    D("meniscus_centre_height", "film-covered sphere centred at 1 - D (in R_e)",
      "femadh/meniscus/geometry.py", (("return 1.0 + self.D", "return 1.0 - self.D"),)),
    D("meniscus_phi_min", "smallest filling angle halved (the sphere point below the flat)",
      "femadh/meniscus/geometry.py",
      (("return math.acos(min(1.0, c)) if c < 1.0 else 0.0",
        "return 0.5 * math.acos(min(1.0, c)) if c < 1.0 else 0.0"),)),
    D("meniscus_film_radius", "film-covered sphere of radius R + 2h",
      "femadh/meniscus/solve.py", (("    Re = radius + h\n", "    Re = radius + 2 * h\n"),)),
    # -- the laws' derivatives and their check
    D("lj82_dpressure", "Lj82 derivative: 3.3 x^4 for 3 x^4", "femadh/laws/lj82.py",
      (("(9.0 * x**10 - 3.0 * x**4)", "(9.0 * x**10 - 3.3 * x**4)"),)),
    D("gw_elastic_dpressure", "GW elastic derivative 1.6 for 3/2", "femadh/laws/gw.py",
      (("return self._c * 1.5 * s.sigma_a**0.5 * gw_integral(0.5, _t(s, h))",
        "return self._c * 1.6 * s.sigma_a**0.5 * gw_integral(0.5, _t(s, h))"),)),
    D("gw_adhesion_energy", "GW adhesion energy 5 % strong", "femadh/laws/gw.py",
      (("return -self._c * s.sigma_a * gw_integral(1.0, _t(s, h))",
        "return -1.05 * self._c * s.sigma_a * gw_integral(1.0, _t(s, h))"),)),
    D("step_energy", "smoothed step law: energy 5 % strong", "femadh/laws/step.py",
      (("return -self._amplitude * self.width * np.logaddexp(0.0, self._x(h))",
        "return -1.05 * self._amplitude * self.width * np.logaddexp(0.0, self._x(h))"),)),
    D("check_law_rtol", "law check tolerance 1e-2 (a 1e-3 wrong derivative passes)",
      "femadh/laws/check.py", (("RTOL = 1e-4", "RTOL = 1e-2"),)),
    # -- independent campaign (2026-11-25)
    D("lj_work_of_adhesion", "LJ work of adhesion A/(12 pi z0^2) for A/(16 pi z0^2)",
      "femadh/laws/lj.py", (("return self.hamaker / (16.0 * math.pi * self.z0**2)",
                              "return self.hamaker / (12.0 * math.pi * self.z0**2)"),)),
    D("capillary_build_no_film", "capillary scene law built without the isotherm's film",
      "femadh/laws/capillary.py", (("CapillaryCondensate(liquid.surface_tension, r_k, film,",
                                    "CapillaryCondensate(liquid.surface_tension, r_k, 0.0,"),)),
    D("gw_gap_offset_sign", "GW laws: t = (h + z_m)/sigma_a (mean summit height sign)",
      "femadh/laws/gw.py", (("return (np.asarray(h, float) - summits.z_m) / summits.sigma_a",
                             "return (np.asarray(h, float) + summits.z_m) / summits.sigma_a"),)),
    D("asperity_step_below_sigma", "smoothed eq 20 step centred at sigma - 5 w (inside the "
      "hard gap)", "femadh/laws/asperity.py", (("return self.sigma + 5 * self.width",
                                                "return self.sigma - 5 * self.width"),)),
    D("green_outside_parameter", "disk displacement outside the load: parameter a/r, not (a/r)^2",
      "femadh/elastic/green.py", (("return a ** 2 / r * outside_factor((a / r) ** 2)",
                                   "return a ** 2 / r * outside_factor(a / r)"),)),
    D("grid_uniform_spacing", "uniform grid: dr = a/N instead of a/(N - 1/2)",
      "femadh/elastic/grid.py", (("dr = radius / (n - 0.5)", "dr = radius / n"),)),
    D("fe_fields_shear_strain", "FE stress recovery: engineering shear strain (no 1/2)",
      "femadh/elastic/fe/fields.py", (("0.5 * (g[0, 1] + g[1, 0]))", "(g[0, 1] + g[1, 0]))"),)),
    D("contact_radius_area", "contact radius sqrt(area / 2 pi)",
      "femadh/contact/complementarity.py", (("math.sqrt(float(problem.areas[A].sum()) / math.pi)",
                                            "math.sqrt(float(problem.areas[A].sum()) / (2 * math.pi))"),)),
    D("step_accepts_unstable", "stepping: a converged but unstable state accepted as a step",
      "femadh/contact/stepping.py", (("    if not (new.converged and new.stable):\n        return False",
                                      "    if not new.converged:\n        return False"),)),
    D("landing_bound_sign", "landing descent: the gap bound held for nodes pulled away (g > 0)",
      "femadh/contact/landing.py", (("at_bound = (w >= upper - 1e-18) & (g < 0)",
                                     "at_bound = (w >= upper - 1e-18) & (g > 0)"),)),
    D("closure_ring_load_half", "closure: rim ring load dD/da at half (2 a K for 4 a K)",
      "femadh/contact/closure/influence.py", (("return 4.0 * a * _ellipk(m) / (math.pi * e_star * (r + a))",
                                               "return 2.0 * a * _ellipk(m) / (math.pi * e_star * (r + a))"),)),
    D("tail_force_pi_r", "tail force beyond the analysis radius: pi R for 2 pi R",
      "femadh/contact/forces.py", (("return float(-2 * math.pi * R * sum(",
                                    "return float(-math.pi * R * sum("),)),
    D("stability_full_contact", "stability: no free node (full contact) reads as unstable",
      "femadh/contact/stability.py", (("    if M.size == 0:\n        return True",
                                       "    if M.size == 0:\n        return False"),)),
    D("moving_edge_interpolation", "moving band: contact edge interpolated with the wrong sign",
      "femadh/discretisation/moving.py", (("(gap - h[k]) / (h[k + 1] - h[k])",
                                           "(h[k] - gap) / (h[k + 1] - h[k])"),)),
    D("edgeband_lead_sign", "follow band: the new band lags the moving edge instead of "
      "leading it", "femadh/discretisation/moving.py",
      (("return x + math.copysign(lim, x - x0) if abs(x - x0) > lim else x",
        "return x - math.copysign(lim, x - x0) if abs(x - x0) > lim else x"),)),
    D("edgeband_inner_gap", "follow band: the band starts half a width beyond the inner "
      "(contact) edge instead of half a width inside it", "femadh/discretisation/moving.py",
      (("inner=lo - self.half)", "inner=lo + self.half)"),)),
    D("carry_unclipped", "carried state: the interpolated surface may cut below sigma",
      "femadh/discretisation/moving.py", (("    w = np.minimum(w, b - new.sigma)\n", ""),)),
    D("carry_wrong_d", "carried state re-solved 0.01 nm off its separation",
      "femadh/discretisation/moving.py",
      (("st = solve_complementarity(new, state.d, w0, tol=tol, max_iter=max_iter, "
        "active0=active0)",
        "st = solve_complementarity(new, state.d + 1e-11, w0, tol=tol, max_iter=max_iter, "
        "active0=active0)"),)),
    D("guard_skips_band_contact", "trapping guard: nodes held at sigma in the band left out",
      "femadh/contact/problem.py",
      (("keep = (h > self.sigma * (1 + 1e-9)) | self.finest_nodes",
        "keep = h > self.sigma * (1 + 1e-9)"),)),
    D("kelvin_saturation_guard", "Kelvin: p/psat = 1 let through (log 0 division)",
      "femadh/meniscus/kelvin.py", (("if not 0.0 < p_ratio < 1.0:", "if not 0.0 < p_ratio <= 1.0:"),)),
    D("bet_isotherm", "BET isotherm: (1 + c x) for (1 - x + c x)",
      "femadh/meniscus/isotherms.py", (("return self.monolayer * self.c * x / ((1 - x) * (1 - x + self.c * x))",
                                        "return self.monolayer * self.c * x / ((1 - x) * (1 + self.c * x))"),)),
    D("shooting_azimuthal_sign", "shooting ODE: azimuthal curvature + sin(psi)/r",
      "femadh/meniscus/shooting.py", (("-(geo.kappa - math.sin(psi) / r)]",
                                       "-(geo.kappa + math.sin(psi) / r)]"),)),
    D("cantilever_factor", "cantilever stiffness E w t^3 / (12 L^3): 3 E I / L^3 without its 3",
      "femadh/instrument/spring.py", (("return youngs_modulus * width * thickness**3 / (4.0 * length**3)",
                                       "return youngs_modulus * width * thickness**3 / (12.0 * length**3)"),)),
    D("readout_loop_trapezoid", "instrument loop integral: trapezoid without the 1/2",
      "femadh/instrument/readout.py", (("np.sum(0.5 * (FF[1:] + FF[:-1]) * np.diff(zz))",
                                        "np.sum((FF[1:] + FF[:-1]) * np.diff(zz))"),)),
    D("fit_jacobian_relative_step", "fit Jacobian: difference divided by rel_step, not "
      "rel_step x_k", "femadh/fitting/lsq.py", (("/ (rel_step * x[k])", "/ rel_step"),)),
    D("psd_nyquist_2pi", "PSD tail check: Nyquist q_N = 2 pi / pixel",
      "femadh/roughness/spectrum.py", (("q_n = math.pi / pixel", "q_n = 2 * math.pi / pixel"),)),
    D("units_areal_density", "fast unit table: um^-2 converted with f^2, not f^-2",
      "femadh/units.py", (('t[pre + "m^-2"] = ("areal_density", f**-2)',
                           't[pre + "m^-2"] = ("areal_density", f**2)'),)),
    D("schema_open_lower_bound", "scene validation: an open lower bound admits its end point",
      "femadh/schema.py", (("not (x >= self.lo if self.lo_closed else x > self.lo)",
                            "not (x >= self.lo if self.lo_closed else x >= self.lo)"),)),
    D("reference_gw_density", "GW judge: summit height density exp(-(z - z_m)^2 / sigma^2)",
      "femadh/reference/gw.py", (("/ (2 * sigma_a**2)) / (math.sqrt(2 * math.pi)",
                                  "/ (sigma_a**2)) / (math.sqrt(2 * math.pi)"),)),
    D("reference_hertz_outside", "Hertz judge: displacement outside the contact with "
      "- a sqrt(r^2 - a^2)", "femadh/reference/hertz.py",
      (("+ a * np.sqrt(ro**2 - a * a))", "- a * np.sqrt(ro**2 - a * a))"),)),
    D("reference_jkr_pull_off", "JKR pull-off 2 pi R dg (the DMT value) for 3/2 pi R dg",
      "femadh/reference/adhesion.py", (("return 1.5 * math.pi * radius * work_of_adhesion",
                                        "return 2.0 * math.pi * radius * work_of_adhesion"),)),
    # -- the corrector's pace (Newton-Krylov, stagnation exit, lattice snaps)
    D("newton_krylov_jacobian_sign", "Newton-Krylov: P'(h) entered with the wrong sign in "
      "the Jacobian's product", "femadh/contact/complementarity.py",
      (("            return a * (product(v) + D_I * v)",
        "            return a * (product(v) - D_I * v)"),)),
    D("newton_gmres_loose", "Newton-Krylov: linear systems solved to 10 % only",
      "femadh/contact/complementarity.py", (("GMRES_RTOL = 1e-6", "GMRES_RTOL = 1e-1"),)),
    D("newton_cholesky_transpose", "trailing Cholesky: U y = r for U^T y = r (U^-1 U^-1)",
      "femadh/contact/linalg.py",
      (("y = trsv(u, r, trans=1, overwrite_x=1)", "y = trsv(u, r, trans=0, overwrite_x=1)"),)),
    D("cholesky_block_trailing", "trailing Cholesky: a solve with the trailing block of the "
      "kept factor for the leading one", "femadh/contact/linalg.py",
      (("blk = kept if k == kept.shape[0] else np.asfortranarray(kept[:k, :k])",
        "blk = kept if k == kept.shape[0] else np.asfortranarray(kept[-k:, -k:])"),)),
    D("checkpoint_factor_transposed", "a checkpoint's preconditioner read back transposed",
      "femadh/contact/linalg.py",
      (("out._kept = np.asfortranarray(kept, dtype=PRECONDITIONER_DTYPE)",
        "out._kept = np.asfortranarray(kept.T, dtype=PRECONDITIONER_DTYPE)"),)),
    D("trailing_lu_block_trailing", "trailing LU: a chord solve with the trailing block of "
      "the factor for the leading one", "femadh/contact/linalg.py",
      (("else np.asfortranarray(self.lu[:k, :k])", "else np.asfortranarray(self.lu[-k:, -k:])"),)),
    D("general_lu_transposed", "the corrector's general LU: the free block of K transposed",
      "femadh/contact/complementarity.py",
      (("            M = np.asfortranarray(K[idx][:, idx])",
        "            M = np.asfortranarray(K[idx][:, idx].T)"),)),
    D("stability_without_law", "stability test (collocated laws): the elastic block factorised "
      "for the Hessian, the law's softening dropped", "femadh/contact/stability.py",
      (("lapack.dpotrf(H.T, lower=False, clean=False, overwrite_a=True)",
        "lapack.dpotrf(problem.S_sym[np.ix_(free, free)], lower=False, clean=False, "
        "overwrite_a=True)"),)),
    D("landing_damps_the_hessian_itself", "landing descent: each trial damping added to the "
      "Hessian itself (a view), earlier dampings carried over",
      "femadh/contact/landing.py",
      (('    M = np.array(H, order="F")\n    M[np.diag_indices_from(M)] += damp',
        "    M = H.T\n    M[np.diag_indices_from(M)] += damp"),)),
    D("newton_givens_rotation", "GMRES: the earlier Givens rotations applied transposed",
      "femadh/contact/linalg.py",
      (("col[i], col[i + 1] = cs[i] * a + sn[i] * c, -sn[i] * a + cs[i] * c",
        "col[i], col[i + 1] = cs[i] * a - sn[i] * c, sn[i] * a + cs[i] * c"),)),
    D("newton_stall_window", "stagnation exit: gives up after 2 iterations without progress",
      "femadh/contact/complementarity.py",
      (("STALL_ITER, STALL_FACTOR = 8, 0.5", "STALL_ITER, STALL_FACTOR = 2, 0.5"),)),
    D("newton_stall_at_fold_decision", "stepping: the fold's decision solve cut short by the "
      "stagnation exit", "femadh/contact/stepping.py",
      (("stall = None if smallest or trapped else STALL_ITER",
        "stall = None if trapped else STALL_ITER"),)),
    # -- the predictor, the acceptance, the peak's warm starts, the member's fold walk
    D("predictor_edge_sign", "edge predictor: the contact edge extrapolated backwards",
      "femadh/contact/stepping.py",
      (("m = int(min(n, round(m_s + (m_s - m_p) * min(x, EDGE_MAX_RATIO))))",
        "m = int(min(n, round(m_s - (m_s - m_p) * min(x, EDGE_MAX_RATIO))))"),)),
    D("predictor_edge_uncapped", "edge predictor: reach not capped at the states' distance",
      "femadh/contact/stepping.py",
      (("m = int(min(n, round(m_s + (m_s - m_p) * min(x, EDGE_MAX_RATIO))))",
        "m = int(min(n, round(m_s + (m_s - m_p) * max(x, EDGE_MAX_RATIO))))"),)),
    D("predictor_edge_shrinks", "edge predictor: a shrinking contact released in advance",
      "femadh/contact/stepping.py",
      (("if state.d == d_p or not m_s or not m_p or m_s - m_p < EDGE_MIN_NODES:",
        "if state.d == d_p or not m_s or not m_p or abs(m_s - m_p) < EDGE_MIN_NODES:"),)),
    D("accept_projection_above_floor", "acceptance: the predicted contact projected to "
      "h = 2 sigma instead of the floor", "femadh/contact/stepping.py",
      (("    out[active] = problem.contour(d)[active] - problem.sigma",
        "    out[active] = problem.contour(d)[active] - 2 * problem.sigma"),)),
    D("accept_released_everywhere", "acceptance: every free node measured against the gap it "
      "reached, not only the released contact", "femadh/contact/stepping.py",
      (("        out = active & ~new.active", "        out = ~new.active"),)),
    D("peak_warm_slope_sign", "peak search: the warm start extrapolated the wrong way",
      "femadh/runner/peak.py",
      (("        w_start = near.w + slope * (d - near.d)",
        "        w_start = near.w - slope * (d - near.d)"),)),
    D("peak_warm_other_branch", "peak search: warm start from a fresh state outside the "
      "bracketing grid states", "femadh/runner/peak.py",
      (("    inside = sorted((s for s in fresh if lo <= s.d <= hi), key=lambda s: abs(s.d - d))",
        "    inside = sorted(fresh, key=lambda s: abs(s.d - d))"),)),
    D("members_walk_sign", "member fold walk: the step toward the fine run's fold taken "
      "away from it", "femadh/runner/members.py",
      (("step = min(2 * step, -j) if j < 0 else 1 if j == 0 else 2 * step",
        "step = min(2 * step, j) if j < 0 else 1 if j == 0 else 2 * step"),)),
    D("newton_stall_on_trapped_grid", "stepping: the stagnation exit also where nodes snap "
      "on their own (a lattice-trapped grid)", "femadh/contact/stepping.py",
      (("trapped = problem.surface_force_stiffness()[0] >= 1.0", "trapped = False"),)),
    D("lattice_snap_threshold", "stepping: a contact snap (~150x the step's work) taken for a "
      "lattice snap", "femadh/contact/stepping.py",
      (("return bool(released <= FOLD_ENERGY_SHARE_MIN_STEP * work + noise)",
        "return bool(released <= 1e3 * FOLD_ENERGY_SHARE_MIN_STEP * work + noise)"),)),
    D("lattice_snap_sign", "stepping: the lattice-snap test on the energy gained, not released",
      "femadh/contact/stepping.py",
      (("released, _, work, noise = step_energy(problem, old, landed, g_old, g_landed)",
        "released, _, work, noise = step_energy(problem, landed, old, g_landed, g_old)"),)),
    D("reference_rigid_lj_peak", "eq 14's peak A R / (6 z0^2) for A R / (8 z0^2)",
      "femadh/reference/rigid_lj.py", (("return hamaker * radius / (8.0 * z0**2)",
                                        "return hamaker * radius / (6.0 * z0**2)"),)),
    # -- the run lifecycle (femadh/runner/lifecycle.py) and the result base
    D("life_failure_status", "lifecycle: a solver failure ends the run \"converged\"",
      "femadh/runner/lifecycle.py",
      (("            result.fail(str(exc), failure_kind(exc))",
        "            result.status, result.error = \"converged\", str(exc)"),)),
    D("life_stop_status", "result: every stop is \"interrupted\" (the time limit too)",
      "femadh/runner/result.py", (("self.status, self.error, self.exit_code = exc.status,",
                                   "self.status, self.error, self.exit_code = \"interrupted\","),)),
    D("life_stop_exit_code", "result: a stop's exit code always 130",
      "femadh/runner/result.py", (("f\"{exc}{where}\", exc.exit_code", "f\"{exc}{where}\", 130"),)),
    D("life_final_check", "lifecycle: no check after the work (a late signal ends "
      "\"converged\")", "femadh/runner/lifecycle.py",
      (("            yield life\n            # a signal that arrived after the last safe point "
        "is still a stop\n            interrupt.check()\n", "            yield life\n"),)),
    D("life_no_running", "lifecycle: summary.json never says \"running\"", "femadh/runner/lifecycle.py",
      (("                life.write_summary(\"running\")", "                pass"),)),
    D("life_interrupted_summary", "lifecycle: a stopped run's last summary still says "
      "\"running\"", "femadh/runner/lifecycle.py",
      (("            life.write_summary()\n",
        "            life.write_summary(\"running\" if result.exit_code else None)\n"),)),
    D("life_no_checkpoint", "lifecycle: the stop hook (the sweep's checkpoint) not called",
      "femadh/runner/lifecycle.py", (("                life.on_stop()", "                pass"),)),
    D("life_untouched", "lifecycle: a folder refused while checked gets a summary written",
      "femadh/runner/lifecycle.py", (("                life._write = None", "                pass"),)),
    D("life_cleanup_on_success_only", "lifecycle: cleanups (writer, logs) only for a "
      "converged run", "femadh/runner/lifecycle.py", (("                fn()", "                result.status == "
                                   "\"converged\" and fn()"),)),
    D("life_sigterm_reraise", "femadh.run: SIGTERM reaches a script as KeyboardInterrupt",
      "femadh/runner/lifecycle.py", (("if result.exit_code == 128 + signal.SIGTERM:",
                                   "if result.exit_code == 128 + signal.SIGINT:"),)),
    D("life_resume_untouched_kept", "contact: a fault after the resumed folder was checked "
      "leaves its summary \"running\"", "femadh/runner/contact.py",
      (("            life.untouched_on = ()\n", ""),)),
    D("meniscus_headline_error", "meniscus headline: the error of the point before the "
      "largest force", "femadh/runner/result.py",
      (("float(np.asarray(c[\"force_error_N\"], float)[k])",
        "float(np.asarray(c[\"force_error_N\"], float)[k - 1])"),)),
    # -- headline guards (a newcomer's trial on a fresh clone)
    D("radius_unbounded", "scene: a sphere radius of metres or parsecs accepted",
      "femadh/scene/parts/body.py", (("lo=0.0, hi=0.1, hi_closed=True),", "lo=0.0),"),)),
    D("peak_end_silent", "run: a largest adhesion at an end of the sweep reported as a peak",
      "femadh/runner/contact.py",
      (("    if sink.peak is None or sink.peak[1] <= 0 or (sink.peak[2] is not None",
        "    if True or sink.peak is None or sink.peak[1] <= 0 or (sink.peak[2] is not None"),)),
    D("report_refused_radius", "report: an accuracy request refused before its first grid "
      "prints an analysis radius of None (a crash)", "femadh/runner/report.py",
      (('    if res.accuracy and res.accuracy.get("steps"):', "    if res.accuracy:"),)),
    # -- stepping: a fold bracketed and located by the indicator's secant (test_fold.py)
    D("fold_secant_sign", "fold search: the indicator's secant extrapolated backwards",
      "femadh/contact/stepping.py",
      (("return d2 + q2 * (d2 - d1) / (q1 - q2)", "return d2 - q2 * (d2 - d1) / (q1 - q2)"),)),
    D("fold_located_coarse", "fold search: a fold located (and decided) to 4 resolution "
      "steps, not 1", "femadh/contact/stepping.py",
      (("return self.far is not None and self.decided and self.steps(state) <= 1",
        "return self.far is not None and self.decided and self.steps(state) <= 4"),
       ("        if n <= 1:\n            return self.far",
        "        if n <= 4:\n            return self.far"),
       ("smallest = abs(d_try - state.d) <= min_step * 1.5",
        "smallest = abs(d_try - state.d) <= min_step * 4.5"))),
    D("fold_off_lattice", "fold search: the indicator's trials off the halving's lattice",
      "femadh/contact/stepping.py",
      (("            return a + self.dir * min(k, n - 1) * h\n",
        "            return a + self.dir * min(max((est - a) * self.dir - 0.5 * h, h),\n"
        "                                      (n - 1) * h)\n"),)),
    D("fold_predictor_brackets", "fold search: a step turned down for the predictor's reach "
      "brackets a fold", "femadh/contact/stepping.py",
      (('if (why == "rejected_predictor" or edge) and k > 1:', "if False:"),)),
    D("fold_no_halving_fallback", "fold search: a landing that does not polish is an error, "
      "no halving fallback", "femadh/contact/stepping.py",
      (("if not (landed.converged and landed.stable) and not halving and jumps_here == 0:",
        "if False:"),)),
    D("landing_roundoff_loose", "landing: the descent stops at a 'round-off' of 1e12 ulps",
      "femadh/contact/landing.py", (("ROUNDOFF_ULPS = 64", "ROUNDOFF_ULPS = 1e12"),)),
    D("landing_roundoff_on_trapped", "landing: the round-off stop also on a lattice-trapped grid",
      "femadh/contact/landing.py",
      (("roundoff=not trapped)", "roundoff=True)"),)),
    D("landing_no_whole_descent", "landing: a polish that fails after the settled descent is "
      "final (no whole descent)", "femadh/contact/landing.py",
      (("if not trapped and not (st.converged and st.stable):", "if False:"),)),
    D("landing_no_fallbacks", "landing: a polish that fails after both descents is final "
      "(no neighbouring edges, no relaxation)", "femadh/contact/landing.py",
      (("st = _relaxed(problem, d, st, descent, tol=tol, max_iter=max_iter)", "pass"),)),
    D("landing_relax_sign", "landing relaxation: the pseudo-time step taken uphill",
      "femadh/contact/landing.py",
      (("            dw = -lu_solve(lu_factor(M), a[idx] * F[idx])",
        "            dw = lu_solve(lu_factor(M), a[idx] * F[idx])"),)),
    D("landing_relax_no_join", "landing relaxation: a free node reaching the floor never "
      "joins the contact set", "femadh/contact/landing.py",
      (("new_A = (A & (pc + adhesion > 0)) | (~A & (h < sigma))",
        "new_A = A & (pc + adhesion > 0)"),)),
    D("landing_relax_ser_inverted", "landing relaxation: the pseudo-time damping follows the "
      "inverse residual ratio", "femadh/contact/landing.py",
      (("mu = RELAX_MU0 * min(1.0, r / r_set) if r_set > 0",
        "mu = RELAX_MU0 * min(1.0, r_set / r) if r > 0"),)),
    D("landing_edges_most_energy", "landing: of the neighbouring edges' stable states the one "
      "of most energy is kept", "femadh/contact/landing.py",
      (("            if e < e_best:", "            if best is None or e > e_best:"),)),
    # -- the estimate's members solved where the headline numbers are read (estimate branch)
    D("mem_fold_lattice_step", "member fold search: each trial two lattice steps beyond the "
      "accepted ones (the fold off the fine run's lattice)", "femadh/runner/members.py",
      (("        d = d_fold + (j + step) * r", "        d = d_fold + (j + 2 * step) * r"),)),
    D("mem_state_neighbour", "member state solved at the separation of the fine run's "
      "previous state", "femadh/runner/members.py",
      (("        c = snaps[k]", "        c = snaps[max(k - 1, 0)]"),)),
    D("mem_uniform_reduced", "reduced members on a uniform grid (its members' branches "
      "differ from the fine one's)", "femadh/runner/members.py",
      (('    if getattr(scene, "grid", None) is None:', "    if False:"),)),
    D("lock_edge_exponent", "contact edge placed from a gap opening like (r - r_e)^2",
      "femadh/runner/members.py",
      (("    q = (g2 / g1) ** (2.0 / 3.0)", "    q = (g2 / g1) ** (1.0 / 2.0)"),)),
    D("lock_phase_off", "members for the deepest state at whole spacings to the edge "
      "(not at the fine grid's fraction)", "femadh/runner/members.py",
      (("    f = x - math.floor(x)", "    f = 0.0"),)),
    D("lock_first_state", "members placed by the edge of the sweep's first state",
      "femadh/runner/members.py",
      (('    snap = (getattr(sink, "last", None) or {}).get("approach")',
        '    snap = sink.committed["approach"][0]'),)),
    D("lock_uniform_off", "a uniform grid's deepest state: the N/2, N/4 members (across the "
      "edge's node-crossing sawtooth), not members placed by the edge",
      "femadh/runner/members.py",
      (('        if why and not why.startswith("a uniform grid"):', "        if why:"),)),
    D("lock_uniform_spacing", "a uniform grid's edge-placed members on the analysis radius "
      "at N/2, N/4 nodes (the fraction of a spacing not kept)", "femadh/runner/members.py",
      (('        member = variant(scene, grid={**g, "spacing": h})',
        '        member = (variant(scene, nodes=int(round(problem.grid.n * h0 / h)))\n'
        '                  if getattr(scene, "grid", None) is None else\n'
        '                  variant(scene, grid={**g, "spacing": h}))'),
       ("    spacings = locked_spacings(problem, contact_edge(problem, snap), g.get(\"band\"), ratio)",
        "    spacings = locked_spacings(problem, contact_edge(problem, snap), g.get(\"band\"), ratio)\n"
        "    h0 = float(problem.grid.nodes[1])"))),
    D("lock_ratio_swap", "uneven Richardson: the two ratios swapped",
      "femadh/runner/estimates.py",
      (("ratio=h1 / h0, ratio2=h2 / h1,\n", "ratio=h2 / h1, ratio2=h1 / h0,\n"),)),
    D("uneven_order_formula", "uneven observed order: r2^p (r1^p - 1) / (r2^p - 1)",
      "femadh/estimate/richardson.py",
      (("        return ratio**p * (ratio2**p - 1.0) / (ratio**p - 1.0) - rho",
        "        return ratio2**p * (ratio**p - 1.0) / (ratio2**p - 1.0) - rho"),)),
    D("fe_green_sign", "FE mesh part of a homogeneous body: Q_FE - Q_Green",
      "femadh/runner/estimates.py",
      (("    return {k: green[k] - v for k, v in fe.items()",
        "    return {k: v - green[k] for k, v in fe.items()"),)),
    # -- a newcomer's second trial: the instrument's whole-sphere pull-off, the meniscus lines
    D("newcomer_pull_off_no_tail", "instrument: the pull-off at the peak without the tail "
      "beyond the analysis radius (the disk's max adhesion)", "femadh/runner/instrument.py",
      (('    F = hl["max_adhesion_N"] + tail\n', '    F = hl["max_adhesion_N"]\n'),)),
    D("newcomer_tail_wrong_state", "instrument: the pull-off's tail taken at d = 0, not at "
      "the max adhesion's state", "femadh/runner/instrument.py",
      (("    tail = tail_force(problem, d)\n", "    tail = tail_force(problem, 0.0)\n"),)),
    D("newcomer_tail_line_basis", "report: the tail line adds F_tail to the path's sampled "
      "pull-off, not to the max adhesion", "femadh/runner/report.py",
      (("f\"{t['max_adhesion_N'] * s:.5g} {unit} (analysis disk) + F_tail \"",
        "f\"{t['sampled_pull_off_N'] * s:.5g} {unit} (analysis disk) + F_tail \""),)),
    D("newcomer_refine_mixed_pair", "instrument readout: a bracket's ends taken as the first "
      "states at its separations (a fold's landing for the fold)", "femadh/runner/instrument.py",
      (("        best = min(pairs, key=apart)\n", "        best = pairs[0]\n"),)),
    D("newcomer_lj_invalid_silenced", "LJ law: a NaN made in the law silenced with its limits "
      "at contact", "femadh/laws/lj.py",
      (('AT_CONTACT = {"over": "ignore", "divide": "ignore", "under": "ignore"}',
        'AT_CONTACT = {"all": "ignore"}'),)),
    D("newcomer_reader_missing_silent", "scene reader: a missing required key not reported "
      "unless its table is missing", "femadh/scene/reader.py",
      (("            elif key.required and (absent or full in self.suggested):",
        "            elif key.required and (absent or True):"),)),
    D("newcomer_meniscus_shooting_exact", "meniscus report: shooting's 0 printed as an "
      "estimated error (± 0)", "femadh/runner/meniscus.py",
      (('estimated = meth in ("fe", "no-film") and np.isfinite(err)',
        'estimated = meth in ("fe", "no-film", "shooting") and np.isfinite(err)'),)),
    D("newcomer_meniscus_few_elements", "meniscus: an FE meridian too short to halve reports "
      "error 0", "femadh/runner/meniscus.py",
      (("    if scene.elements < 4:\n        return math.nan\n",
        "    if scene.elements < 4:\n        return 0.0\n"),)),
    D("newcomer_meniscus_error_scale", "meniscus report: the F/4πRγ error not divided by "
      "4πRγ (by 4πR)", "femadh/runner/meniscus.py",
      (("err / unit4 if estimated else None", "err / (4 * math.pi * R) if estimated else "
        "None"),)),
    # -- one home for the error machinery: the adaptive run on the refine loop, typed
    #    failure kinds, a study point's time limit (issue 21)
    D("adaptive_kind_by_words", "adaptive grid: the remedy picked by the words 'analysis "
      "radius' in the error, not by the failure's kind", "femadh/runner/adaptive.py",
      (("        if res.failure_kind == REFINE_RADIUS:",
        "        if \"analysis radius\" in (res.error or \"\"):"),)),
    D("accuracy_bound_unrefined", "accuracy mode: a result beyond Derjaguin-Bradley's bound "
      "ends the request instead of doubling N", "femadh/runner/accuracy.py",
      (('REFINE_NODES = ("trapping", "bound")', 'REFINE_NODES = ("trapping",)'),)),
    D("refine_radius_kind_swapped", "refine loops: a trapped grid grows the disk (the radius "
      "remedy keyed to the wrong kind)", "femadh/runner/accuracy.py",
      (('REFINE_RADIUS = "analysis_radius"', 'REFINE_RADIUS = "trapping"'),)),
    D("lifecycle_kind_dropped", "lifecycle: a guard's failure recorded without its kind",
      "femadh/runner/lifecycle.py",
      (("            result.fail(str(exc), failure_kind(exc))",
        "            result.fail(str(exc))"),)),
    D("guard_radius_untyped", "contact guard: a contact at the analysis radius raised as a "
      "plain GuardError", "femadh/estimate/guards.py",
      (("        raise AnalysisRadiusError(", "        raise GuardError("),)),
    D("envelope_uneven_factor", "oscillating members at uneven ratios: the coarser "
      "difference scaled by 1/r2^p (the model's factor only for even ratios)",
      "femadh/estimate/richardson.py",
      (("    return (ratio**p - 1) / (ratio**p * (ratio2**p - 1))", "    return ratio2**-p"),)),
    D("relative_nan_met", "accuracy: a NaN error part dropped by max() (an unknown error "
      "called met)", "femadh/runner/estimates.py",
      (("        if not all(math.isfinite(comp.get(part, 0.0)) for part in (\"total\", \"tail\")):",
        "        if False:"),)),
    D("headline_scan_nodal", "headline: the contact-gap scan read as a nodal field",
      "femadh/contact/problem.py",
      (('    def pointwise_pressure(self, h):\n        """Sum of the effect pressures (Pa) of every law evaluated pointwise at gaps h (a scan\n        of gaps, whatever its length: never read as a nodal field)."""\n        return self._sum("pressure", h)',
        '    def pointwise_pressure(self, h):\n        """Sum of the effect pressures (Pa) of every law evaluated pointwise at gaps h (a scan\n        of gaps, whatever its length: never read as a nodal field)."""\n        return self.pressure(h)'),)),
    D("bound_untyped", "runner: the bounds guard's refusal not typed as BoundError",
      "femadh/runner/estimates.py",
      (("        raise BoundError(\n", "        raise GuardError(\n"),)),
    D("adaptive_stop_refines", "adaptive grid: a trial stopped by its time limit is refined "
      "and run again", "femadh/runner/adaptive.py",
      (("    if res.status in STOPPED:\n        return res.status",
        "    if res.status == \"interrupted\":\n        return res.status"),)),
    D("adaptive_budget_plus_one", "adaptive grid: MAX_TRIALS + 1 runs",
      "femadh/runner/adaptive.py",
      (("Budget(MAX_TRIALS - 1, MAX_NODES)", "Budget(MAX_TRIALS, MAX_NODES)"),)),
    D("adaptive_members_failed_same_h", "adaptive grid: failed members rerun at the same "
      "spacing", "femadh/runner/adaptive.py",
      (('        ahead["next"] = (family, h * MAX_FACTOR)',
        '        ahead["next"] = (family, h)'),)),
    D("adaptive_last_failure_lost", "adaptive grid: the reason the request ends (a tail the "
      "disk cannot hold) dropped", "femadh/runner/adaptive.py",
      (('                   else ahead["failure"])', '                   else None)'),)),
    D("adaptive_uncapped_recorded", "adaptive grid: the trial records and refines from the "
      "spacing asked for, not the capped one it ran", "femadh/runner/adaptive.py",
      (("    return Trial(family, h, spacing, op.grid.n, op, follow)",
        "    return Trial(family, spacing, spacing, op.grid.n, op, follow)"),)),
    D("adaptive_any_valueerror_budget", "adaptive grid: any ValueError of a member read as the "
      "node budget's refusal", "femadh/runner/adaptive.py",
      (("    except NodeBudgetError:     # the member would exceed MAX_NODES",
        "    except ValueError:     # the member would exceed MAX_NODES"),)),
    D("adaptive_tail_short_as_nodes", "adaptive grid: a request the tail keeps short asks for "
      "more nodes", "femadh/runner/adaptive.py",
      (('        if last["tail_rel_error"] > SAFETY * target:', "        if False:"),)),
    D("adaptive_radius_need_power", "adaptive grid: the radius needed from the tail's decay "
      "with the power p, not 1/p", "femadh/runner/adaptive.py",
      (("a1 * (t1 / tail_target) ** (1 / p) * 1e6", "a1 * (t1 / tail_target) ** p * 1e6"),)),
    # -- the adaptive loop sized by the estimate's observed order (refine)
    D("refine_order_assumed_always", "adaptive loop: every refinement sized with the assumed ORDER, "
      "the observed order ignored", "femadh/runner/adaptive.py",
      (("    order = _order(step, history)", "    order = ORDER"),)),
    D("refine_order_not_applied", "adaptive loop: the observed order recorded but the factor taken "
      "at ORDER", "femadh/runner/adaptive.py",
      (("factor = (safety * target / err) ** (1.0 / order)",
        "factor = (safety * target / err) ** (1.0 / ORDER)"),)),
    D("refine_order_half", "adaptive loop: the observed order over twice the log spacing ratio",
      "femadh/runner/adaptive.py",
      (("p = math.log(e0 / e1) / math.log(h0 / h1)",
        "p = math.log(e0 / e1) / (2 * math.log(h0 / h1))"),)),
    D("refine_order_unclamped", "adaptive loop: the observed order not clamped to ORDER_BOUNDS",
      "femadh/runner/adaptive.py",
      (("        return min(ORDER_BOUNDS[1], max(ORDER_BOUNDS[0], p))", "        return p"),)),
    D("refine_order_any_family", "adaptive loop: the order observed across a grown analysis radius",
      "femadh/runner/adaptive.py",
      (('                or prev.get("analysis_radius_m") != step["analysis_radius_m"]\n',
        ""),)),
    D("refine_order_across_follow", "adaptive loop: the order observed between a static band "
      "and one that follows the edge", "femadh/runner/adaptive.py",
      (('                or ("follow_m" in prev) != ("follow_m" in step)):',
        "                or False):"),)),
    D("refine_order_rising_estimate", "adaptive loop: an estimate that rose read as an order (clamped "
      "to its floor)", "femadh/runner/adaptive.py",
      (("        if e0 <= e1:\n            return ORDER", "        if False:\n            return ORDER"),)),
    D("refine_order_oldest_step", "adaptive loop: the order from the oldest qualifying run, not the "
      "latest", "femadh/runner/adaptive.py",
      (("    for prev in reversed(history):", "    for prev in history:"),)),
    D("refine_safety_far_everywhere", "adaptive loop: SAFETY at every distance from the target (no "
      "near aim)", "femadh/runner/adaptive.py",
      (("    return min(AIM, max(SAFETY, s))", "    return SAFETY"),)),
    D("refine_safety_exponent", "adaptive loop: the near aim's exponent -(1 - c) instead of "
      "-(1 - c)/c", "femadh/runner/adaptive.py",
      (("ratio ** (-(1.0 - c) / c) if ratio > 0", "ratio ** (-(1.0 - c)) if ratio > 0"),)),
    D("mem_fold_solves_uncounted", "reduced member: a fold search that falls back leaves its "
      "corrector solves uncounted", "femadh/runner/members.py",
      (("        solves, m.solves = solves + 1, m.solves + 1     # counted as made",
        "        solves = solves + 1     # counted as made"),)),
    # -- the estimate's cost (estcost): member states solved only where the numbers need them
    D("est_zero_pair_shifted", "member zero-force radius: the interval before the fine run's "
      "sign change read first", "femadh/runner/members.py",
      (("        sts = [m.state(branch, snaps[branch], j) for j in (k, k + 1)]",
        "        sts = [m.state(branch, snaps[branch], j) for j in (k - 1, k)]"),)),
    D("est_zero_pair_wide", "member zero-force radius: the crossing interpolated over two "
      "grid steps", "femadh/runner/members.py",
      (("        sts = [m.state(branch, snaps[branch], j) for j in (k, k + 1)]",
        "        sts = [m.state(branch, snaps[branch], j) for j in (k, k + 2)]"),)),
    D("est_zero_pair_unchecked", "member zero-force radius: the interval's value kept without "
      "a sign change in it", "femadh/runner/members.py",
      (("        if math.isfinite(rc):\n            return rc",
        "        if True:\n            return rc"),)),
    D("est_deepest_always_skipped", "family members skip the deepest state even without "
      "edge-placed members", "femadh/runner/estimates.py",
      (("    deepest = locked is None or not LOCKED_DEEPEST_ONLY\n",
        "    deepest = False\n"),)),
    D("est_locked_not_applied", "edge-placed members solved but their grid part not applied",
      "femadh/runner/estimates.py",
      (("    if locked is not None and levels:", "    if locked is not None and not levels:"),)),
    D("est_fold_stall_inverted", "member fold decision: the whole budget where it should stop "
      "on stagnation, stagnation where it should not", "femadh/runner/members.py",
      (("stall_iter=None if step == 1 and not FOLD_DECISION_STALL",
        "stall_iter=None if step == 1 and FOLD_DECISION_STALL"),)),
    D("roughness_interrupt_ignored", "validation/roughness.py: a run stopped by a signal does "
      "not stop the script (its loops go on)", "validation/roughness.py",
      (('    if res.status == "interrupted":\n        raise Interrupted(res.exit_code - 128)',
        '    if False:\n        raise Interrupted(res.exit_code - 128)'),)),
    D("overwrite_keeps_vtk", "--overwrite leaves the previous run's vtk folder",
      "femadh/io/run_folder.py",
      (('           "vtk", "approach.pvd", "retract.pvd",', '           "approach.pvd", '
        '"retract.pvd",'),)),
    D("resume_of_a_finished_run", "--resume of a converged run runs it again instead of saying "
      "there is nothing to resume", "femadh/io/run_folder.py",
      (('            if _finished(prev):\n                raise OutputError(f"{what}: it has '
        'finished, there is nothing to resume")',
        '            if False:\n                raise OutputError(f"{what}: it has '
        'finished, there is nothing to resume")'),)),
    D("study_time_limit_unrun", "study: a point stopped by its time limit recorded as never "
      "run", "femadh/studies/sweep.py",
      (('return rec.get("status") in ("converged", "failed", "time limit")',
        'return rec.get("status") in ("converged", "failed")'),)),
    # -- the peak bracket bounded by folds (tests/test_peak_after_jump.py)
    D("peakfold_landing_prev", "peak: a landing bracketed by the last state before the "
      "fold (across it), not by itself", "femadh/runner/sink.py",
      (("        if start:\n            prev = snap\n", "        if False:\n            prev = snap\n"),)),
    D("peakfold_end_open", "peak: a fold's last state not the end of its piece's bracket",
      "femadh/runner/sink.py",
      (("            self.peak = [branch, f, prev, snap, snap if end else None]\n",
        "            self.peak = [branch, f, prev, snap, None]\n"),
       ("            self._need_next = not end", "            self._need_next = True"))),
    D("peakfold_landing_force", "peak: a landing's F_ex taken from the state before the fold",
      "femadh/runner/sink.py",
      (("(jump.before, f_before), (jump.after, f_after))))",
        "(jump.before, f_before), (jump.after, f_before))))"),)),
    D("peakfold_tie_narrower", "peak: a tie at one separation goes to the narrower bracket",
      "femadh/runner/sink.py",
      (("if p[2] is None or p[4] is None or _extent(r) > _extent(p) or (",
        "if p[2] is None or p[4] is None or _extent(r) < _extent(p) or ("),)),
    D("peakfold_pieces_unsplit", "members: the fine run's branch walked as one piece (the "
      "folds ignored; re-pointed in session 8: the sink records the pieces)",
      "femadh/runner/sink.py",
      (("        if start or not ps:\n", "        if not ps:\n"),
       ("        if end:\n            ps[-1][2] = True", "        if False:\n            ps[-1][2] = True"))),
    D("peakfold_checkpoint_dropped", "checkpoint: the fold states of the peak's bracket not "
      "saved (a resumed search from re-solved ones)", "femadh/runner/checkpoint.py",
      (("    data.update(_fold_data(sink))\n", ""),)),
    D("peakfold_search_last_grid", "follow band: the peak searched on the sweep's last grid, "
      "not on its states' own", "femadh/runner/estimates.py",
      (('peak_adhesion(getattr(sink, "peak_problem", problem), prev, best, nxt, scene)',
        "peak_adhesion(problem, prev, best, nxt, scene)"),)),
    D("peakfold_resume_order", "resume: the folds not replayed (the resumed bracket reaches "
      "across them)",
      "femadh/runner/sink.py",
      (('            while folds.get(b) and (folds[b][0]["d_land_m"] - d) * sign <= 0:',
        '            while folds.get(b) and (folds[b][0]["d_land_m"] - d) * sign < -1e-9:'),)),
    # -- the band that follows the sigma-gap contact edge (issue 21 goal 1, edgefollow)
    D("ef_zone_fraction_half", "follow band: the cohesive zone ends at half ZONE_FRACTION "
      "of the softening", "femadh/discretisation/moving.py",
      (("ok = np.flatnonzero(s >= ZONE_FRACTION * top)",
        "ok = np.flatnonzero(s >= 0.5 * ZONE_FRACTION * top)"),)),
    D("ef_zone_step_ignored", "follow band: a meniscus edge inside the zone (its secant "
      "softening) left out of the zone", "femadh/discretisation/moving.py",
      (("        if e >= ZONE_FRACTION * top:", "        if False:"),)),
    D("ef_edge_ratio_max", "edge ratio: the larger of LJ's softening and the meniscus secant, "
      "not their sum", "femadh/discretisation/plan.py",
      (("                soft += law.edge_softening(floor)",
        "                soft = max(soft, law.edge_softening(floor))"),)),
    D("ef_follow_safe_member_power", "follow-safe spacing: the coarsest member sqrt 2 "
      "coarser, not 2x", "femadh/discretisation/plan.py",
      (("return math.inf if ratio <= 0 else h * EDGE_SAFE / MIN_MEMBER_RATIO**2 / ratio",
        "return math.inf if ratio <= 0 else h * EDGE_SAFE / MIN_MEMBER_RATIO / ratio"),)),
    D("ef_lead_one_step", "travel-aware band: built to cover one grid step's travel, not "
      "LEAD_STEPS", "femadh/discretisation/moving.py",
      (("            return (min(lo, lo + k * move[0]), max(hi, hi + k * move[1]))",
        "            return (min(lo, lo + move[0]), max(hi, hi + move[1]))"),)),
    D("ef_travel_across_landing", "travel-aware band: the travel read across a landing's "
      "jump", "femadh/discretisation/moving.py",
      (("        if prev is not None and not landed and abs(d - prev[0]) > 0:",
        "        if prev is not None and abs(d - prev[0]) > 0:"),)),
    D("ef_widen_unbounded", "follow band: a failed landing falls back to a static band of "
      "any size", "femadh/discretisation/moving.py",
      (("            self.spacing) <= WIDEN_MAX_NODES",
        "            self.spacing) <= 10 * WIDEN_MAX_NODES"),)),
    D("ef_follow_decided_uncapped", "adaptive plan: follow decided by the uncapped static "
      "member's count", "femadh/runner/adaptive.py",
      (("    if family.count(0.98 * safe_spacing(problem)) <= FOLLOW_NODES:",
        "    if family.count(spacing) <= FOLLOW_NODES:"),)),
    D("ef_follow_static_grading", "adaptive plan: the follow band keeps the static family's "
      "grading (2 % per node)", "femadh/runner/adaptive.py",
      (("        fam = GridFamily(family.radius, family.band, FOLLOW_GRADING_SPACINGS * h)",
        "        fam = GridFamily(family.radius, family.band, family.grading)"),)),
    D("ef_zone_not_in_band", "follow band: the outer edge at the floor gap (the zone out of "
      "the band)", "femadh/runner/tracing.py",
      (("                    zone_gap(problem.effects, floor), floor * (1 + 1e-6),",
        "                    floor * (1 + 2e-6), floor * (1 + 1e-6),"),)),
    # -- review fixes after the session-7 merge
    D("follow_by_refinement", "adaptive: the follow band chosen by the accuracy's refined "
      "spacing, not the trapping cap alone", "femadh/runner/adaptive.py",
      (("if family.count(0.98 * safe_spacing(problem)) <= FOLLOW_NODES:",
        "if family.count(min(h, 0.98 * safe_spacing(problem))) <= FOLLOW_NODES:"),)),
    # -- the max-adhesion bracket across a grid exchange, a resume, a failed fold re-solve
    D("sb_exchange_prev_copy", "grid exchange: the next candidate's neighbour left on the "
      "old grid (the last state's copy not taken)", "femadh/runner/tracing.py",
      (("            sink._prev = (prev[0], copies[id(s)])",
        "            pass"),)),
    D("sb_exchange_prev_landing", "grid exchange: a landing neighbour left on the old grid",
      "femadh/runner/tracing.py",
      (("            sink._prev = (prev[0], replace(s))\n            moved.append(sink._prev[1])",
        "            pass"),)),
    D("sb_landing_row_prev", "resume: the landing's record (no surface) stays the next "
      "candidate's neighbour", "femadh/runner/sink.py",
      (("                self._prev = (branch, snap)\n            return",
        "                pass\n            return"),)),
    D("sb_fold_peak_stand_in", "resume: a fold state that is the peak replaced by its "
      "smaller neighbour", "femadh/runner/sink.py",
      (("                if x[3] is s:\n", "                if False:\n"),)),
    D("sb_nan_stand_in", "resume: a neighbour that did not re-solve stands in with F_ex NaN",
      "femadh/runner/sink.py",
      (("math.nan, f0) if math.isfinite(f0) else None", "math.nan, f0) if True else None"),)),
    D("sb_resolve_error_escapes", "resume: the neighbour's ConvergenceError aborts the resume",
      "femadh/runner/sink.py",
      (("            except ConvergenceError:\n                ok = False",
        "            except ValueError:\n                ok = False"),)),
    D("sb_fold_rise_linear", "max at a fold end: the rise to the fold as the secant times the "
      "resolution", "femadh/runner/estimates.py",
      (("    rise = abs(best.f_ex - prev.f_ex) * math.sqrt(r) / (math.sqrt(step + r) - "
        "math.sqrt(r))", "    rise = abs(best.f_ex - prev.f_ex) * r / step"),)),
    D("sb_fold_end_landing", "max at a fold end: the fold looked up by its landing",
      "femadh/runner/estimates.py",
      (("enumerate(folds) if before is best)", "enumerate(folds) if _ is best)"),)),
    # -- session 8 (member19): the members' kink search, a member state on a saddle, the
    # curve's pieces recorded by the sink
    D("kink_intersection_sign", "kink model: the secants' intersection with the slopes' "
      "difference of the wrong sign", "femadh/runner/peak.py",
      (("ds[j1]) / (s_in - s_out)", "ds[j1]) / (s_out - s_in)"),)),
    D("kink_meets_anywhere", "kink model: the secants' meeting point kept wherever it lies "
      "(not only between the two samples)", "femadh/runner/peak.py",
      (("                not lo - xatol / 2 <= x <= hi + xatol / 2:",
        "                not -math.inf <= x:"),)),
    D("kink_never_smooth", "kink search: a smooth maximum searched by the secants' meeting "
      "point (the parabola's vertex only as a fallback)", "femadh/runner/peak.py",
      (("            if _smooth_here(ds, fs, i):", "            if False:"),)),
    D("kink_no_straddle", "kink search: a proposal next to the best sample is not moved to "
      "xatol / 2 (the bracket never closed by a straddle)", "femadh/runner/peak.py",
      (("            if abs(x - b) < xatol / 2:\n                x = b + math.copysign(",
        "            if False:\n                x = b + math.copysign("),)),
    D("kink_one_side", "window miss: only the side below the window searched",
      "femadh/runner/peak.py",
      (("            refine(s_lo, s_hi)\n", "            refine(s_lo, s_hi)\n            break\n"),)),
    D("kink_stop_loose", "kink search: stops once the bracket is 10 xatol wide",
      "femadh/runner/peak.py",
      (("            if c - a <= xatol:\n                return b",
        "            if c - a <= 10 * xatol:\n                return b"),)),
    D("window_stop_at_centre", "windowed member search: stops when its best state is far "
      "from the window's edge", "femadh/runner/peak.py",
      (("min(top - lo, hi - top) <= edge_stop * (hi - lo)",
        "min(top - lo, hi - top) >= edge_stop * (hi - lo)"),)),
    D("saddle_keeps_saddle", "member state: the landing from the carried state discarded "
      "(the saddle kept)", "femadh/runner/members.py",
      (("            return st\n        return landed", "            return st\n        return st"),)),
    D("saddle_land_from_fine_grid", "member state: landed from the saddle's own surface "
      "shifted by the carried state's largest gap change", "femadh/runner/members.py",
      (("        landed = land(self.problem, st.d, w0, tol=self.scene.tolerance,",
        "        landed = land(self.problem, st.d, 2 * st.w - w0, tol=self.scene.tolerance,"),)),
    D("pieces_same_d_kept", "sink pieces: a state at the separation of the piece's last one "
      "kept as a second state", "femadh/runner/sink.py",
      (("        elif not (ps[-1][0] and ps[-1][0][-1].d == snap.d):",
        "        elif True:"),)),
    D("pieces_no_end", "sink pieces: a fold's last state does not close its piece",
      "femadh/runner/sink.py",
      (("        if end:\n            ps[-1][2] = True", "        if False:\n            ps[-1][2] = True"),)),
    D("pieces_landing_joins", "sink pieces: a landing joins the piece before the fold",
      "femadh/runner/sink.py",
      (("        if start or not ps:\n            ps.append(", "        if not ps:\n            ps.append("),)),
    # -- fig4fast3: the stability certificate and the corrector's carried products
    D("cert_tail_dropped", "stability certificate: the nodes outside the edge block left out "
      "of the bound", "femadh/contact/stability.py",
      (("room = CERT_LIMIT - self.tail(e, b)", "room = CERT_LIMIT"),)),
    D("cert_limit_above_one", "stability certificate: bound limit 1.2 (certifies saddles)",
      "femadh/contact/stability.py", (("CERT_LIMIT = 0.9\n", "CERT_LIMIT = 1.2\n"),)),
    D("cert_far_block", "stability certificate: the block taken from the axis, not the edge",
      "femadh/contact/stability.py",
      (("X = np.array(self.rinv[k - b:k, k - b:k], order=\"F\")",
        "X = np.array(self.rinv[:b, :b], order=\"F\")"),)),
    D("cert_not_reversed", "stability certificate: softening in natural node order",
      "femadh/contact/stability.py",
      (("return cert.certifies(np.maximum(-D[::-1], 0.0))",
        "return cert.certifies(np.maximum(-D, 0.0))"),)),
    D("cert_sign", "stability certificate: the stiffening taken as the softening",
      "femadh/contact/stability.py",
      (("return cert.certifies(np.maximum(-D[::-1], 0.0))",
        "return cert.certifies(np.maximum(D[::-1], 0.0))"),)),
    D("cert_q_column", "stability certificate: the trace read one column short",
      "femadh/contact/stability.py",
      (("self.q[:k - b, k - 1]", "self.q[:k - b, k - b - 1]"),)),
    D("carried_on_set_change", "corrector: the step's h, P, K w carried into an iteration "
      "whose contact set changed", "femadh/contact/complementarity.py",
      (("if sigma is not None and (same or\n"
        "                                  CARRY_RELEASES and not np.any(new_A & I)):",
        "if sigma is not None:"),)),
    D("refute_no_margin", "edge-block refutation at lambda_max > 0.5 (refutes positive "
      "definite Hessians)", "femadh/contact/stability.py",
      (("1.0 + REFUTE_MARGIN)", "0.5 + REFUTE_MARGIN)"),)),
    D("refute_stiffening_kept", "edge-block refutation where some free node stiffens",
      "femadh/contact/stability.py",
      (("if not (np.all(np.isfinite(aD)) and np.all(aD <= 0)):",
        "if not np.all(np.isfinite(aD)):"),
       ("return cert.refutes(-aD[::-1])", "return cert.refutes(np.maximum(-aD[::-1], 0.0))"))),
    D("deferred_block_off_by_one", "deferred refresh: the block one node smaller than the "
      "refuted one also reported not covered", "femadh/contact/linalg.py",
      (("            if self.n - m >= not_pd:", "            if self.n - m >= not_pd - 1:"),)),
    D("deferred_refutes_own_block", "deferred refresh: a smaller free set refuted by the "
      "refresh's own block", "femadh/contact/complementarity.py",
      (("refutes=lambda k: refuted_positive_definite(problem, D, n - k))",
        "refutes=lambda k: refuted_positive_definite(problem, D, m))"),)),
    # -- stepping/landing: a contact unzipping node by node (issue 21, test_snap_cost.py)
    D("snap_next_no_lattice_check", "stepping: a next-node landing taken without the "
      "lattice-snap test (a contact's snap landed by the corrector)",
      "femadh/contact/stepping.py",
      (("if near is not None and lattice_snap(problem, state, near, g_state,\n"
        "                                                     total_force(problem, near)):",
        "if near is not None:"),)),
    D("snap_next_shift_sign", "stepping: the next-node landing's disk moved against the edge "
      "(grown on a retract)", "femadh/contact/stepping.py",
      (("-1 if grid_step > 0 else 1, tol=tol, stats=sweep.work,",
        "1 if grid_step > 0 else -1, tol=tol, stats=sweep.work,"),)),
    D("snap_next_unstable", "landing: a next-node candidate taken without its stability",
      "femadh/contact/landing.py",
      (("if not (st.stable and m_new is not None", "if not (m_new is not None"),)),
    D("snap_next_edge_either_way", "landing: a next-node candidate whose edge kept its place "
      "or moved against the edge's way taken", "femadh/contact/landing.py",
      (("1 <= (m_new - m) * sign <= 2", "-2 <= (m_new - m) * sign <= 2"),)),
    D("snap_next_no_downhill", "landing: a next-node candidate taken without the downhill "
      "test (its energy may lie above the descent's start)", "femadh/contact/landing.py",
      (("if not _downhill(problem, d, start, e_start, st.w):",
        "if False and not _downhill(problem, d, start, e_start, st.w):"),)),
    D("snap_downhill_loose", "landing: the downhill test lets the energy rise by its own size",
      "femadh/contact/landing.py",
      (("if not np.isfinite(e) or e > e_prev + _roundoff(problem, w, e):",
        "if not np.isfinite(e) or e > e_prev + abs(e_prev) + _roundoff(problem, w, e):"),)),
    D("snap_rhythm_past", "snap: the rhythm's first trial aimed past the expected fold",
      "femadh/contact/snap.py",
      (("self.target = d_fold + direction * (s - SNAP_MARGIN) * min_step",
        "self.target = d_fold + direction * (s + SNAP_MARGIN) * min_step"),)),
    D("snap_rhythm_any_spacing", "snap: any three snaps taken for a rhythm",
      "femadh/contact/snap.py",
      (("if 1 <= s <= SNAP_RHYTHM_MAX and 0.5 * s0 <= s <= 2 * s0:",
        "if 1 <= s <= SNAP_RHYTHM_MAX:"),)),
    D("snap_rhythm_creep_two", "snap: the rhythm creeps two resolution steps at a time "
      "(a fold located to two steps)", "femadh/contact/snap.py",
      (("            return d + direction * min_step\n",
        "            return d + direction * 2 * min_step\n"),)),
    D("snap_cycle_any_residual", "snap: a decision whose residual falls by orders of "
      "magnitude taken for a cycle", "femadh/contact/snap.py",
      (("CYCLE_RTOL = 1e-3", "CYCLE_RTOL = 1.0"),)),
    D("snap_cycle_nodes_ignored", "snap: the cycle told by the residuals alone",
      "femadh/contact/snap.py",
      (("    return all(last[i][3] == last[i + CYCLE_PERIOD][3]\n               and abs(",
        "    return all(True\n               and abs("),)),
    D("snap_decision_cut_always", "snap: every unconverged decision probe taken as the "
      "decision", "femadh/contact/snap.py",
      (("    if cycling(probe[\"history\"]):", "    if True:"),)),
    # -- branch fixrev1: the reviewer's defects (validation/results/seeded_defects_fixrev1.md)
    D("rev1_window_best_sample", "kink_peak: a window that missed returns the best sample, "
      "not refined", "femadh/runner/peak.py",
      (("    got = refine(lo, hi)\n    return float(pts[got]), float(got), xatol\n\n\ndef _kink",
        "    got = max((x for x in pts if pts[x] is not None), key=lambda x: pts[x])\n"
        "    return float(pts[got]), float(got), xatol\n\n\ndef _kink"),)),
    D("rev1_window_refine_inside_only", "kink_peak: the final refinement only inside the "
      "window", "femadh/runner/peak.py",
      (("    got = refine(lo, hi)\n    return float(pts[got]), float(got), xatol\n\n\ndef _kink",
        "    got = refine(w_lo, w_hi)\n    return float(pts[got]), float(got), xatol\n\n\n"
        "def _kink"),)),
    D("rev1_saddle_any_set", "members: a landed saddle kept on any contact set",
      "femadh/runner/members.py",
      (("                not np.array_equal(landed.active, st.active):",
        "                False:"),)),
    D("rev1_saddle_set_size_loose", "members: a landed saddle kept on a contact set one node "
      "larger or smaller", "femadh/runner/members.py",
      (("                not np.array_equal(landed.active, st.active):",
        "                abs(int(landed.active.sum()) - int(st.active.sum())) > 1:"),)),
    D("rev1_cert_squares_copied", "certificate: the cumulated squares built from a squared "
      "temporary and a copy (3 n^2 at the build's peak)", "femadh/contact/stability.py",
      (("        q = np.empty_like(rinv, order=\"F\")\n        np.square(rinv, out=q)\n"
        "        for j in range(1, n):\n            np.add(q[:, j], q[:, j - 1], out=q[:, j])\n"
        "        self.q = q\n",
        "        self.q = np.asfortranarray(np.cumsum(rinv * rinv, axis=1))\n"),)),
    D("rev1_cert_squares_skip_column", "certificate: the cumulated squares miss the first "
      "column's addition", "femadh/contact/stability.py",
      (("        for j in range(1, n):\n            np.add(q[:, j], q[:, j - 1]",
        "        for j in range(2, n):\n            np.add(q[:, j], q[:, j - 1]"),)),
    D("rev1_green_arrays_old", "resources: 8 dense arrays counted (the run holds 11)",
      "femadh/scene/resources.py", (("GREEN_ARRAYS = 11", "GREEN_ARRAYS = 8"),)),
    D("rev1_late_factor_uncounted", "complementarity: a deferred refresh factorised by "
      "covers() not counted", "femadh/contact/complementarity.py",
      (("    n_factor += int(late and not pre.deferred)", "    n_factor += 0"),)),
    D("rev1_late_factor_always_counted", "complementarity: a deferred refresh counted whether "
      "or not covers() factorised it", "femadh/contact/complementarity.py",
      (("    n_factor += int(late and not pre.deferred)", "    n_factor += int(late)"),)),
    D("rev1_refute_stiffening", "stability: refutation where some free nodes stiffen, "
      "their stiffening dropped", "femadh/contact/stability.py",
      (("    if not (np.all(np.isfinite(aD)) and np.all(aD <= 0)):",
        "    aD = np.minimum(aD, 0.0)\n    if not np.all(np.isfinite(aD)):"),)),
    # -- the landing's scan of farther contact edges (pull03, issue 21 goal 1)
    D("scan_one_way", "landing scan: farther edges tried only towards a smaller contact",
      "femadh/contact/landing.py",
      (("            best = least((k, -k))", "            best = least((-k,))"),)),
    D("scan_skips_nearest", "landing scan: starts one node beyond the nearest farther edge",
      "femadh/contact/landing.py",
      (("range(max(abs(x) for x in EDGE_SHIFTS) + 1, EDGE_SCAN + 1)",
        "range(max(abs(x) for x in EDGE_SHIFTS) + 2, EDGE_SCAN + 1)"),)),
    D("scan_goes_on", "landing scan: does not stop at the first distance with a landing",
      "femadh/contact/landing.py",
      (("            if best is not None:\n                break\n",
        "            if best is not None:\n                pass\n"),)),
    D("scan_without_shifts", "landing scan: runs with the neighbouring edges turned off",
      "femadh/contact/landing.py",
      (("    if best is None and EDGE_SHIFTS:", "    if best is None:"),)),
    D("sep_climbs", "pull-off landing: the separated state taken even above the descent's "
      "energy", "femadh/contact/landing.py",
      (("            problem.energy(st.w, d) < problem.energy(w, d):",
        "            problem.energy(st.w, d) < problem.energy(w, d) + 1.0:"),)),
    # -- the same, after review (branch fixrev2, test_snap_cost.py)
    D("snap_hold_none", "snap: a next-node landing kept without the branch going on from "
      "it (a metastable state one node in beside the pull-off)", "femadh/contact/snap.py",
      (("NEXT_NODE_HOLD_STEPS = 2", "NEXT_NODE_HOLD_STEPS = 0"),)),
    D("snap_hold_no_acceptance", "stepping: the hold's steps taken whatever the corrector "
      "gave", "femadh/contact/stepping.py",
      (("        if not _accept(new, w_pred, d, problem, act):\n            return None\n"
        "        g_new = total_force(problem, new)\n        if crossed_fold(",
        "        g_new = total_force(problem, new)\n        if False and crossed_fold("),)),
    D("snap_hold_backwards", "snap: the hold probed back toward the last state, not on",
      "femadh/contact/snap.py",
      (("        at = step(at, d_land + direction * k * min_step)\n",
        "        at = step(at, d_land - direction * k * min_step)\n"),)),
    D("snap_aim_repeated", "stepping: the rhythm's aim kept after its trial was turned down "
      "as too far for the predictor", "femadh/contact/stepping.py",
      (("            rhythm.forget_aim()\n", "            pass\n"),)),
    D("snap_path_end_only", "landing: the downhill test samples the path's end only",
      "femadh/contact/landing.py",
      (("PATH_SAMPLES = 16", "PATH_SAMPLES = 1"),)),
    # -- the snap rhythm in the checkpoint, cycles told by their sets (branch snaphome,
    #    test_snaphome_resume.py, test_snaphome_cycling.py)
    D("snaphome_rhythm_not_saved", "checkpoint: the snap rhythm not written (a resume "
      "mid-unzipping with a fresh one)", "femadh/runner/checkpoint.py",
      (("    data.update(_rhythm_data(st.snap_rhythm))\n", ""),)),
    D("snaphome_rhythm_not_restored", "stepping: a trace started from a state of its branch "
      "ignores the state's rhythm", "femadh/contact/stepping.py",
      (("    rhythm = snap.SnapRhythm.restored(state.snap_rhythm, branch)",
        "    rhythm = snap.SnapRhythm()"),)),
    D("snaphome_rhythm_any_branch", "snap: a rhythm restored on any branch (the approach's on "
      "the retract)", "femadh/contact/snap.py",
      (("        if snapshot is not None and snapshot[0] == branch:",
        "        if snapshot is not None:"),)),
    D("snaphome_rhythm_fresh_snapshot", "stepping: each grid state keeps a fresh rhythm, not "
      "the trace's", "femadh/contact/stepping.py",
      (("        state.snap_rhythm = rhythm.snapshot(branch)",
        "        state.snap_rhythm = snap.SnapRhythm().snapshot(branch)"),)),
    D("snaphome_rhythm_aim_lost", "checkpoint: the rhythm's aim read back as none",
      "femadh/runner/checkpoint.py",
      (("    target, creep_to = (None if math.isnan(x) else float(x) for x in z[\"snap_aim\"])",
        "    target, creep_to = None, None"),)),
    D("snaphome_rhythm_float32", "checkpoint: the rhythm's separations kept in float32",
      "femadh/runner/checkpoint.py",
      (("\"snap_folds\": np.array(folds, dtype=float)",
        "\"snap_folds\": np.array(folds, dtype=np.float32)"),)),
    D("snaphome_cycle_sizes", "snap: a cycle told by the sizes of the contact sets, not the "
      "sets", "femadh/contact/snap.py",
      (("    return all(last[i][3] == last[i + CYCLE_PERIOD][3]\n",
        "    return all(last[i][1] == last[i + CYCLE_PERIOD][1]\n"),)),
    D("snaphome_history_next_set", "complementarity: the history records the next "
      "iteration's contact set, not the one iterated on", "femadh/contact/complementarity.py",
      (("                                     A.tobytes()))",
        "                                     new_A.tobytes()))"),)),
    # -- session 9 (estcost): a small member's states factorise their own Jacobian
    D("estcost_factor_inverted", "members: the nearby factorisation reused below the node "
      "threshold and not above it", "femadh/runner/peak.py",
      (("    return problem.grid.n >= MEMBER_FACTOR_MIN_NODES",
        "    return problem.grid.n < MEMBER_FACTOR_MIN_NODES"),)),
    D("estcost_factor_fine_too", "peak search: the fine run's own fresh states drop their "
      "chord factorisation too (its headline moves)", "femadh/runner/peak.py",
      (("            not (reuse and not reuse_factor(problem)):",
        "            reuse_factor(problem):"),)),
    D("estcost_factor_grid_states_inherit", "members: the states at the fine run's grid "
      "separations still inherit the nearest member state's factorisation",
      "femadh/runner/members.py",
      (("        if near and reuse_factor(self.problem):", "        if near:"),)),
    D("estcost_factor_fresh_inherit", "peak search: a small member's fresh states still "
      "inherit the nearby factorisation", "femadh/runner/peak.py",
      (("            not (reuse and not reuse_factor(problem)):",
        "            True:"),)),
    # -- the sigma-gap branch traced in its edge radius (branch sigedge, test_sigma_edge.py)
    D("sedge_no_lam", "sigma-edge branch: the law pressure not scaled with the grid (K0 w - P)",
      "femadh/contact/sigma_edge.py",
      (("        R = self.K0[k:] @ w - lam * P[k:]\n", "        R = self.K0[k:] @ w - P[k:]\n"),)),
    D("sedge_d_column", "sigma-edge branch: the held nodes left out of the Jacobian's d column",
      "femadh/contact/sigma_edge.py",
      (("            M[:, -1] = self._kheld\n", "            M[:, -1] = 0.0\n"),)),
    D("sedge_tangent_shape", "sigma-edge branch: dd/dc with the contour's motion halved",
      "femadh/contact/sigma_edge.py",
      (("        ds = self.sphere.slope(r) * r / st.c\n",
        "        ds = 0.5 * self.sphere.slope(r) * r / st.c\n"),)),
    D("sedge_tangent_lam", "sigma-edge branch: dd/dc without the law pressure's d lam/dc",
      "femadh/contact/sigma_edge.py",
      (("- st.P[k:] / self.r0 - lam * Jdh[k:]", "- lam * Jdh[k:]"),)),
    D("sedge_force_area", "sigma-edge branch: the force with the areas scaled by lam, not lam^2",
      "femadh/contact/sigma_edge.py",
      (("        return st.lam * st.lam * float(self.areas0 @ st.p_net)",
        "        return st.lam * float(self.areas0 @ st.p_net)"),)),
    D("sedge_multiplier_row", "sigma-edge branch: the multipliers from the unscaled stiffness "
      "(P - K0 w)", "femadh/contact/sigma_edge.py",
      (("        p[:k] = P[:k] - (self.K0[:k] @ w) / lam", "        p[:k] = P[:k] - self.K0[:k] @ w"),)),
    D("sedge_tangent_held", "sigma-edge branch: dd/dc with the held edge node's gap moving "
      "with the contour", "femadh/contact/sigma_edge.py",
      (("        dh[k + 1:] = ds[k + 1:]", "        dh[k:] = ds[k:]"),)),
    D("sedge_fold_sign", "sigma-edge retract: the downward march stops where d(c) still rises",
      "femadh/contact/sigma_edge.py",
      (("        return s.c <= c_low or s.dd_dc > 0\n", "        return s.c <= c_low or s.dd_dc < 0\n"),)),
    D("sedge_tail_sign", "sigma-edge: the laws between two radii with the sign flipped",
      "femadh/contact/sigma_edge.py",
      (("    return float(2 * math.pi * R * (u[1] - u[0]))",
        "    return float(2 * math.pi * R * (u[0] - u[1]))"),)),
    D("sedge_held_gap", "sigma-edge branch: the held nodes' displacement without sigma",
      "femadh/contact/sigma_edge.py",
      (("        w[:k + 1] = d + shape[:k + 1] - sigma\n", "        w[:k + 1] = d + shape[:k + 1]\n"),)),
    D("sedge_homotopy_guard", "sigma-edge start: the homotopy's states taken without "
      "complementarity", "femadh/contact/sigma_edge.py",
      (("            if trial is None or not branch.complementary(trial):",
        "            if trial is None:"),)),
    D("sedge_hertz_guess", "sigma-edge: Hertz's start with the contact's interference doubled",
      "femadh/contact/sigma_edge.py",
      (("    delta = c * c / R\n    d = branch.sigma - delta\n",
        "    delta = 2 * c * c / R\n    d = branch.sigma - delta\n"),)),
    # -- the edge-branch route (femadh/runner/edge_route.py)
    D("eroute_richardson_denominator", "edge route: Richardson's extrapolation over "
      "(r^p + 1)", "femadh/runner/edge_route.py",
      (("    ext = f3 + (f3 - f2) / (r ** p - 1)", "    ext = f3 + (f3 - f2) / (r ** p + 1)"),)),
    D("eroute_guard_factor", "edge route: an erratic family's error without the guard's "
      "factor", "femadh/runner/edge_route.py",
      (("    bound = max(abs(f3 - f2), abs(f2 - f1) / q) / (q - 1)",
        "    bound = abs(f3 - f2)"),)),
    D("eroute_met_absolute", "edge route: the family stops on an absolute error (N) against "
      "the relative target", "femadh/runner/edge_route.py",
      (("            allowed = target * abs(fam.value)\n",
        "            allowed = target\n"),)),
    D("eroute_no_stability", "edge route: the curve and the jump-out without the runner's "
      "stability test", "femadh/runner/edge_route.py",
      (("        if not br.stable(s):\n            lost = s",
        "        if False:\n            lost = s"),)),
    D("eroute_pilots_static", "edge route: pilots scenes whose grid would not follow the edge",
      "femadh/runner/edge_route.py",
      (("            and edge_trap_ratio(scene, member()) > EDGE_TRAP_MARGIN)):\n        return None\n",
        "            and edge_trap_ratio(scene, member()) > EDGE_TRAP_MARGIN)):\n        pass\n"),)),
    D("eroute_headline_extrapolated", "edge route: the headline the extrapolation, not the "
      "finest member's state", "femadh/runner/edge_route.py",
      (('    hl["max_adhesion_N"] = fam.value', '    hl["max_adhesion_N"] = fam.extrapolation'),)),
    D("eroute_eq20_passes", "edge route: eq 20's adhesion passes the static conditions",
      "femadh/runner/edge_route.py",
      (('    if gap is None or gap.contact_model != "complementarity" or gap.adhesion:',
        '    if gap is None or gap.contact_model != "complementarity":'),)),
    D("eroute_lost_side", "edge route: the stability check on the wrong side of the largest "
      "force", "femadh/runner/edge_route.py",
      (("    if lost is not None and lost.c >= best.c:",
        "    if lost is not None and lost.c <= best.c:"),)),
    D("eroute_low_fold", "edge route: a pilot's fold at its lowest edge radius taken",
      "femadh/runner/edge_route.py",
      (("    if r.fold.c < c_ref / PILOT_SPAN / LOW:", "    if False:"),)),
    # -- the routed run's sweep outputs (branch routefull: femadh/runner/edge_sweep.py,
    #    femadh/contact/sigma_edge.py's placing and polishing, edge_route's modes)
    D("rfull_land_at_fold", "routed sweep: the jump-out landed at the fold's own separation",
      "femadh/runner/edge_sweep.py",
      (("    d_land = min(d_fold + resolution, min(beyond))\n",
        "    d_land = d_fold\n"),)),
    D("rfull_landing_committed", "routed sweep: the landing committed as a sweep state",
      "femadh/runner/edge_sweep.py",
      (("            if first[0]:              # the landing: a jump's record, not a sweep state\n"
        "                first[0] = False\n                return\n",
        "            if first[0]:              # the landing: a jump's record, not a sweep state\n"
        "                first[0] = False\n"),)),
    D("rfull_unstable_committed", "routed sweep: a branch state the runner's test rejects "
      "committed", "femadh/runner/edge_sweep.py",
      (("            if not st.stable:\n                out[\"lost\"] = d\n",
        "            if False:\n                out[\"lost\"] = d\n"),)),
    D("rfull_place_at_bracket_end", "routed sweep: a state placed at its bracket's end, not "
      "at its separation", "femadh/contact/sigma_edge.py",
      (("    for s in (hi, lo):\n        if s.d == d:\n            return s\n",
        "    for s in (hi, lo):\n        return s\n"),)),
    D("rfull_polish_at_branch_d", "routed sweep: a state polished at the branch state's "
      "separation, not the sweep's", "femadh/contact/sigma_edge.py",
      (("    new = solve_complementarity(pb, d, st.w, tol=tol, max_iter=max_iter, active0=active)",
        "    new = solve_complementarity(pb, st.d, st.w, tol=tol, max_iter=max_iter,\n"
        "                                active0=active)"),)),
    D("rfull_fold_state_sign", "routed sweep: the fold's runner state with the contact "
      "pressure added to the laws'", "femadh/contact/sigma_edge.py",
      (("    p_net = sum(p_eff.values()) - st.p_c\n", "    p_net = sum(p_eff.values()) + st.p_c\n"),)),
    D("rfull_deep_not_extended", "routed sweep: the branch not traced on to the sweep's "
      "deepest separation", "femadh/contact/sigma_edge.py",
      (("    if top.d > d_deep:\n        run = tr.march(", "    if False:\n        run = tr.march("),)),
    D("rfull_met_absolute", "edge route: the outputs' accuracy gate on an absolute error (N)",
      "femadh/runner/edge_route.py",
      (("    return sum(abs(v) for v in _error_parts(scene, fam).values()) <= target * abs(fam.value)",
        "    return sum(abs(v) for v in _error_parts(scene, fam).values()) <= target"),)),
    D("rfull_peak_full", "edge route: route = 'peak' computes the sweep's outputs",
      "femadh/runner/edge_route.py",
      (("            if getattr(scene, \"route\", \"auto\") == \"peak\" or not _met(",
        "            if getattr(scene, \"route\", \"auto\") == \"speak\" or not _met("),)),
    D("rfull_judged_warning", "edge route: what it judges printed as a warning",
      "femadh/runner/edge_route.py",
      (("JUDGED = (NOTE + \"edge route: the max adhesion", "JUDGED = (\"edge route: the max adhesion"),)),
    D("rfull_lost_continues", "edge route: a branch the runner's test rejects before its "
      "fold reported converged", "femadh/runner/edge_route.py",
      (("    if info[\"lost\"] is not None:\n        raise ConvergenceError(\n"
        "            f\"edge route: the branch stops being stable",
        "    if False:\n        raise ConvergenceError(\n"
        "            f\"edge route: the branch stops being stable"),)),

    # -- the solve made cheaper (branch fig4solve): the descent's round-off rejections, the
    #    first refinement's order
    D("lmrej_full_descent_too", "landing descent: rises within round-off settle the whole "
      "descent too (roundoff off)", "femadh/contact/landing.py",
      (("            if roundoff and ROUNDOFF_REJECTS and np.isfinite(e_new) and \\\n",
        "            if ROUNDOFF_REJECTS and np.isfinite(e_new) and \\\n"),)),
    D("lmrej_not_counted", "landing descent: a rise within round-off raises the damping "
      "without counting towards settling", "femadh/contact/landing.py",
      (("                flat += 1\n                if flat >= ROUNDOFF_STEPS:\n"
        "                    return w, True\n",
        "                flat += 0\n                if flat >= ROUNDOFF_STEPS:\n"
        "                    return w, True\n"),)),
    D("lmrej_takes_risen_step", "landing descent: settles on the risen trial point, not on w",
      "femadh/contact/landing.py",
      (("                if flat >= ROUNDOFF_STEPS:\n                    return w, True\n"
        "            lam *= 4",
        "                if flat >= ROUNDOFF_STEPS:\n                    return w_new, True\n"
        "            lam *= 4"),)),
    D("first_order_old", "adaptive loop: the first refinement at the assumed ORDER again",
      "femadh/runner/adaptive.py",
      (("        return min(ORDER_BOUNDS[1], max(ORDER_BOUNDS[0], p))\n    return FIRST_ORDER\n",
        "        return min(ORDER_BOUNDS[1], max(ORDER_BOUNDS[0], p))\n    return ORDER\n"),)),
    D("first_order_on_rise", "adaptive loop: an estimate that rose sized at FIRST_ORDER",
      "femadh/runner/adaptive.py",
      (("        if e0 <= e1:\n            return ORDER\n",
        "        if e0 <= e1:\n            return FIRST_ORDER\n"),)),
    D("eroute_alternating_extrapolated", "edge route: alternating differences extrapolated "
      "(the sign test dropped: a ratio of sizes reads them as an order)",
      "femadh/runner/edge_route.py",
      (("    if not (f1 - f2) * (f2 - f3) > 0:\n        return math.nan, f3, bound\n    p = math.log((f1 - f2) / (f2 - f3)) / math.log(r)",
        "    p = math.log(abs((f1 - f2) / (f2 - f3))) / math.log(r)"),)),
    D("sedge_problem_subgrid_unscaled", "sigma edge: a state's problem keeps the sub-grid "
      "step on the reference nodes (its pressure off by lam^-2)",
      "femadh/contact/edge_branch.py",
      (("    if ref.integrated:\n        pb.integrated = {",
        "    if False:\n        pb.integrated = {"),)),
    D("eroute_sweep_range", "edge route: taken where the sweep never presses in to the largest "
      "force's state", "femadh/runner/edge_route.py",
      (("    if pil is not None and min(scene.d_values) >= pil.retract.best.d:",
        "    if pil is not None and min(scene.d_values) >= pil.retract.best.d + 1.0:"),)),
    D("eroute_fold_beyond_sweep", "edge route: a jump-out reported beyond the sweep's end",
      "femadh/runner/edge_route.py",
      (("    if lost is None and r.fold.d > max(scene.d_values):",
        "    if lost is None and r.fold.d > max(scene.d_values) + 1.0:"),)),
    D("eroute_resume_sweep_folder", "edge route: a resumed folder of the sweep's path taken "
      "down the route", "femadh/runner/adaptive.py",
      (('    return grid.get("route") != "edge-branch"',
        '    return grid.get("route") == "edge-branch"'),)),
    D("eroute_pilot_failure_raised", "edge route: a pilot that cannot be traced raises out of "
      "the run", "femadh/runner/edge_route.py",
      (("    except (ConvergenceError, ValueError):\n        # a pilot that cannot be traced",
        "    except ValueError:\n        # a pilot that cannot be traced"),)),
    D("eroute_failure_part", "edge route: an unmet request blames the smallest error part",
      "femadh/runner/edge_route.py",
      (('        big = max(("grid", "tail", "tolerance"), key=lambda n: abs(comp[n]))',
        '        big = min(("grid", "tail", "tolerance"), key=lambda n: abs(comp[n]))'),)),
    # -- the estimate's lattice part and a uniform grid's members (session 10, estimate)
    # (lattice_part_off and lattice_tooth_max retired by sigedge: the lattice part is off,
    # femadh.runner.estimates.LATTICE_PART, so peak.lattice_tooth no longer runs)
    # (the release period moved with the refuted lattice part to validation/sigma_edge_limits.py
    # by latmend; its test, test_release_period_is_one_spacing_of_the_edge, stays)
    D("lattice_period_quarter", "release period quartered (the lattice column's window misses "
      "the tooth's trough)", "validation/sigma_edge_limits.py",
      (("    return abs(nxt.d - prev.d) / dn if dn else None",
        "    return abs(nxt.d - prev.d) / (4 * dn) if dn else None"),)),
    D("cohesive_edge_any_step", "cohesive edge found wherever a sub-grid step is reachable",
      "femadh/runner/estimates.py",
      (("    return secant > 0 and secant > problem.surface_force_stiffness()[2]",
        "    return secant > 0"),)),
    D("cohesive_edge_scaled", "cohesive edge only where the step's secant exceeds 4x LJ's",
      "femadh/runner/estimates.py",
      (("    return secant > 0 and secant > problem.surface_force_stiffness()[2]",
        "    return secant > 0 and secant > 4 * problem.surface_force_stiffness()[2]"),)),
    # -- the sweep against the sigma-edge branch on the map's sigma = 0.489 nm point (sigedge)
    # (lattice_part_on retired by latmend: the lattice part and its flag are deleted)
    D("cohesive_note_missing", "a run where a cohesive zone acts at the contact edge does not "
      "name the route that traces it", "femadh/runner/estimates.py",
      (("        res.warnings.append(COHESIVE_NOTE)", "        pass"),)),
    D("cohesive_note_gate_inverted", "the cohesive-edge note gated on the sweep having no peak "
      "(latmend: the gate is cohesive_edge and the sink's peak)", "femadh/runner/estimates.py",
      (('    if "max_adhesion_N" in hl and getattr(sink, "peak", None) is not None \\',
        '    if "max_adhesion_N" in hl and getattr(sink, "peak", None) is None \\'),)),
    D("uniform_half_member_rule", "uniform members chosen by the N/2 member's softening",
      "femadh/runner/estimates.py",
      (("member_safe(problem, (n - 0.5) / (n // 4 - 0.5))",
        "member_safe(problem, (n - 0.5) / (n // 2 - 0.5))"),)),
    D("uniform_sqrt2_nominal_ratio", "uniform sqrt2 members: Richardson at sqrt 2, not their "
      "spacings' ratio", "femadh/runner/estimates.py",
      (("        return (n - 0.5) / (n1 - 0.5), out, (n1 - 0.5) / (n2 - 0.5)",
        "        return 2**0.5, out, (n1 - 0.5) / (n2 - 0.5)"),)),
    D("uniform_ratio2_dropped", "uniform sqrt2 members: the estimate ignores the second ratio",
      "femadh/runner/estimates.py",
      (("                                   ratio=ratio, ratio2=ratio2, decay_order=decay).items():",
        "                                   ratio=ratio, decay_order=decay).items():"),)),
    # -- the corrector made cheaper (branch corrector): releases carry h, P, K w; the first
    #    step at a set solved to GMRES_RTOL_NEW_SET; GMRES's rotations in Python floats; the
    #    preconditioner's block size checked once
    D("corr_carry_additions", "corrector: an iteration that adds contact nodes carries its "
      "gaps and products too (the new nodes never put on the floor)",
      "femadh/contact/complementarity.py",
      (("CARRY_RELEASES and not np.any(new_A & I)):", "CARRY_RELEASES):"),)),
    D("corr_carry_inverted", "corrector: carried only when nodes are added, not released",
      "femadh/contact/complementarity.py",
      (("CARRY_RELEASES and not np.any(new_A & I)):", "CARRY_RELEASES and np.any(new_A & I)):"),)),
    D("corr_loose_every_step", "corrector: every Newton step solved to the loose tolerance",
      "femadh/contact/complementarity.py",
      (("GMRES_RTOL_NEW_SET if res == math.inf else GMRES_RTOL)", "GMRES_RTOL_NEW_SET)"),)),
    D("corr_loose_1e-2", "corrector: the first step at a set solved to 1e-2",
      "femadh/contact/complementarity.py",
      (("GMRES_RTOL_NEW_SET = 1e-4\n", "GMRES_RTOL_NEW_SET = 1e-2\n"),)),
    D("corr_gmres_rotation_sign", "GMRES: an earlier rotation applied with the wrong sign",
      "femadh/contact/linalg.py",
      (("col[i], col[i + 1] = cs[i] * a + sn[i] * c, -sn[i] * a + cs[i] * c",
        "col[i], col[i + 1] = cs[i] * a + sn[i] * c, sn[i] * a + cs[i] * c"),)),
    D("corr_gmres_norm_squared", "GMRES: the new direction's norm squared, not its norm",
      "femadh/contact/linalg.py",
      (("col.append(math.sqrt(w @ w))", "col.append(w @ w)"),)),
    D("corr_block_unchecked", "preconditioner: a solve reuses the last block whatever its size",
      "femadh/contact/linalg.py",
      (("        if blk[0] != k or k <= 0:\n", "        if blk[0] is None or k <= 0:\n"),)),
    # -- the Krylov products in single precision (branch pace, seeded_defects_pace.md)
    D("pace_single_stale", "single products: the float32 copy kept when the problem's K is "
      "replaced", "femadh/contact/complementarity.py",
      (("if held is None or held[0] is not problem.K:", "if held is None:"),)),
    D("pace_single_half", "single products: K copied in half precision",
      "femadh/contact/complementarity.py",
      (("held = (problem.K, np.asarray(problem.K, dtype=np.float32))",
        "held = (problem.K, np.asarray(problem.K, dtype=np.float16))"),)),
    D("pace_single_rows", "single products: K_II's rows taken one node off",
      "femadh/contact/complementarity.py",
      (("K_II = _single_k(problem)[m:, m:]", "K_II = _single_k(problem)[m - 1:-1, m:]"),)),
    D("pace_single_no_law", "single products: the law's stiffness left out of GMRES's operator",
      "femadh/contact/complementarity.py",
      (("            return a * (product(v) + D_I * v)", "            return a * product(v)"),)),
    # -- an adaptive trial's estimate deferred until the loop keeps it (branch pace2,
    #    validation/results/seeded_defects_pace2.md)
    D("pace2_complete_judged_only", "deferred estimate: completed with the judged numbers "
      "only (the members' folds and zero-force radii never solved)",
      "femadh/runner/estimates.py",
      (("        out = assemble(copy.deepcopy(parts0), *settle(False),",
        "        out = assemble(copy.deepcopy(parts0), *settle(True),"),)),
    D("pace2_defer_when_met", "deferred estimate: the rest deferred where the judged numbers "
      "meet the request, made at once where they miss it", "femadh/runner/estimates.py",
      (("    if not grid_e + tail_e > target or all(",
        "    if grid_e + tail_e > target or all("),)),
    D("pace2_rest_no_zero_radius", "deferred estimate: a member's rest without its zero-force "
      "radii", "femadh/runner/members.py",
      (("            for branch in res.branches:\n                key = f\"r_c_at_zero_force_",
        "            for branch in ():\n                key = f\"r_c_at_zero_force_"),)),
    D("pace2_kept_not_completed", "adaptive loop: the kept trial's deferred estimate left "
      "partial", "femadh/runner/adaptive.py",
      (("            complete_estimate(res)          # the kept trial's estimate made whole",
        "            pass"),)),
    D("pace2_superseded_completed", "adaptive loop: every trial's deferred estimate completed "
      "(a superseded trial's rest solved)", "femadh/runner/adaptive.py",
      (("        tr.operator = None            # run: its dense operator need not outlive it",
        "        tr.operator = None            # run: its dense operator need not outlive it\n"
        "        from .estimates import complete_estimate\n        complete_estimate(res)"),)),
    D("pace2_trials_not_deferred", "adaptive loop: its trials run without the request to "
      "defer (every superseded trial's whole estimate solved)", "femadh/runner/adaptive.py",
      (("            with deferring(target if estimate is True else None):",
        "            with deferring(None):"),)),
    # -- the contact solve's hot path without scipy's wrappers (branch hotpath,
    #    seeded_defects_hotpath.md)
    D("hotpath_getrs_transposed", "direct LAPACK: the LU solve of the transposed system",
      "femadh/contact/linalg.py",
      (("    x, info = _GETRS(lu, piv, b, trans=0, overwrite_b=False)",
        "    x, info = _GETRS(lu, piv, b, trans=1, overwrite_b=False)"),)),
    D("hotpath_trtrs_untransposed", "direct LAPACK: GMRES's C-ordered R handed to trtrs "
      "as if Fortran-ordered", "femadh/contact/linalg.py",
      (("    x, info = _TRTRS(R.T, g, overwrite_b=False, lower=True, trans=True, unitdiag=False)",
        "    x, info = _TRTRS(R, g, overwrite_b=False, lower=True, trans=True, unitdiag=False)"),)),
    D("hotpath_diagonal_copy", "diagonal view: a Fortran-ordered matrix's diagonal taken "
      "from a copy (the adds lost)", "femadh/contact/linalg.py",
      (("        return M.T.reshape(-1)[::M.shape[0] + 1]",
        "        return M.reshape(-1)[::M.shape[0] + 1]"),)),
    D("hotpath_sum_aliased", "laws' sum: the first law's array itself (its -0.0 kept, a "
      "cached array added to)", "femadh/contact/problem.py",
      (("                    out = v + 0.0\n", "                    out = v\n"),)),
    D("hotpath_sum_shape_unchecked", "laws' sum: a first law's value taken as the sum "
      "whatever its shape (a law constant in h not broadcast to the nodes)",
      "femadh/contact/problem.py",
      (("                        and h.dtype == _F8 and v.shape == h.shape and v.ndim > 0):",
        "                        and h.dtype == _F8 and v.ndim > 0):"),)),
    D("hotpath_finite_any", "laws' finite check: passes unless every node is not finite",
      "femadh/contact/problem.py",
      (("        if not finite.all():", "        if not finite.any():"),)),
    D("hotpath_set_key_stale", "corrector: the active set's bytes not updated with the set "
      "(later iterations compare against the first set)", "femadh/contact/complementarity.py",
      (("        A, A_key = new_A, new_key\n", "        A = new_A\n"),)),
    # -- what a user sees: Ctrl-C at any moment, an ignored SIGINT, the figures' words and
    #    their prepared layout, a study's estimates (seeded_defects_ui.md)
    D("ui_sigign_overridden", "a run replaces a SIGINT its parent set to SIG_IGN",
      "femadh/interrupt.py",
      (("           if signal.getsignal(s) is not signal.SIG_IGN}",
        "           if True}"),)),
    D("ui_no_startup_handler", "the program's Ctrl-C while it imports itself is a traceback",
      "femadh/cli.py",
      (("if _as_program() and signal.getsignal(signal.SIGINT) is signal.default_int_handler:",
        "if False:"),)),
    D("ui_parser_unguarded", "the parser built outside main's guard (a Ctrl-C there is a "
      "traceback)", "femadh/cli.py",
      (("def _main(argv, program=False):\n    try:\n",
        "def _main(argv, program=False):\n    signal.signal(signal.SIGINT, "
        "signal.default_int_handler)\n    _parser()\n    try:\n"),)),
    D("ui_main_import_unguarded", "python -m femadh: a Ctrl-C while femadh.cli is imported "
      "is a traceback", "femadh/__main__.py",
      (("except KeyboardInterrupt:\n", "except ImportError:\n"),)),
    D("ui_error_two_digits", "the stated force's error to two digits (the figure's old rule; "
      "re-pointed: the value then to the place of its error's second digit)",
      "femadh/io/plots.py",
      (('    e = float(f"{abs(err):.1g}")', '    e = float(f"{abs(err):.2g}")'),)),
    D("ui_inset_no_error", "the inset states the max adhesion without its error",
      "femadh/io/plots.py",
      (("    return f\"max adhesion {force_text(hl['max_adhesion_N'], e_f)} at d = {d} nm\"",
        "    return f\"max adhesion {force_text(hl['max_adhesion_N'], None)} at d = {d} nm\""),)),
    D("ui_slider_words", "panel (d) calls the force the force on the slider",
      "femadh/io/plots.py",
      (('ax[3].set(xlabel="d (nm)", ylabel=f"force on the sphere ({fl}), adhesion < 0",',
        'ax[3].set(xlabel="d (nm)", ylabel=f"force on slider ({fl})",'),)),
    D("ui_prepared_ticks_differ", "the prepared panels' ticks made with other properties",
      "femadh/io/plots.py",
      (("            axis.get_major_ticks(_TICKS)",
        "            axis.get_major_ticks(_TICKS)\n            axis.set_tick_params(length=5)"),)),
    D("ui_prepared_not_taken", "the six panels never take the prepared figure",
      "femadh/io/plots.py",
      (('    fig = _PREPARED.pop("panels", None)',
        '    fig = _PREPARED.pop("panels", None) and None'),)),
    D("ui_study_reuses_unestimated", "a study with estimates reuses points computed without",
      "femadh/studies/sweep.py",
      (("    return _ORDER.index(point_estimate(rec)) >= _ORDER.index(ESTIMATE_NAMES[estimate])",
        "    return True"),)),
    D("ui_study_legacy_as_estimated", "an earlier femadh's record taken as estimated",
      "femadh/studies/sweep.py",
      (('    return ("errors" if any(k.endswith("_error") or k.startswith("max_force_N[")\n'
        '                            for k in rec) else "none")',
        '    return "errors"'),)),
    D("study_meniscus_estimate_as_asked", "a meniscus point's record says what it was asked "
      "(peak), not what its run did (errors)", "femadh/studies/executors.py",
      (('            rec["estimate"] = "errors"\n', '            pass\n'),)),
    D("ui_study_estimate_unrecorded", "a point's record says 'errors' whatever its run "
      "estimated", "femadh/studies/executors.py",
      (('           "estimate": ESTIMATE_NAMES[estimate], "femadh": code_id(), "pid": os.getpid()}',
        '           "estimate": "errors", "femadh": code_id(), "pid": os.getpid()}'),)),
    D("ui_study_no_estimate_ignored", "study sweep --no-estimate still estimates",
      "femadh/cli.py",
      (('                          estimate="peak" if args.no_estimate else True,',
        '                          estimate=True,'),)),
    # -- the Green operator assembled in blocks of rows, a non-finite stiffness refused
    #    (branch greenop, seeded_defects_greenop.md)
    D("greenop_block_edge_side", "block assembly: a node on its annulus' inner edge taken "
      "outside its own disk", "femadh/elastic/green.py",
      (('first_in = np.searchsorted(e, nodes, side="left")',
        'first_in = np.searchsorted(e, nodes, side="right")'),)),
    D("greenop_block_bounds_swapped", "block assembly: the block's inside/outside column "
      "bounds taken from its last and first rows", "femadh/elastic/green.py",
      (("lo, hi = first_in[i0], first_in[i1 - 1]", "lo, hi = first_in[i1 - 1], first_in[i0]"),)),
    D("greenop_block_band_strict", "block assembly's ragged band: r < a inside (r = a outside)",
      "femadh/elastic/green.py", (("inside = a >= rr", "inside = a > rr"),)),
    D("greenop_block_band_outside_dropped", "block assembly: the ragged band's outside "
      "pairs left at zero", "femadh/elastic/green.py",
      (("            band[~inside] = _outside(rr[~inside], a[~inside])\n", ""),)),
    D("greenop_stiffness_unguarded", "K = C^-1 of a compliance with a NaN returned as NaNs",
      "femadh/elastic/operator.py",
      (("if not np.all(np.isfinite(self._stiffness)):", "if False:"),)),
    D("route_family_grid_alone", "edge route: the family stops once its grid part alone meets "
      "the target (tail and tolerance left out)", "femadh/runner/edge_route.py",
      (("                allowed -= tail + tolerance\n", ""),)),
    D("route_family_tail_ignored", "edge route: a tail beyond SAFETY of the target does not "
      "stop the family", "femadh/runner/edge_route.py",
      (("                if tail_stops and tail > SAFETY * allowed:", "                if False:"),)),
    D("route_family_tail_stops_always", "edge route: a tail stops the family where the disk "
      "cannot grow any more", "femadh/runner/edge_route.py",
      (("                if tail_stops and tail > SAFETY * allowed:",
        "                if tail > SAFETY * allowed:"),)),
    D("route_family_no_share_runs_on", "edge route: tail and tolerance that leave the grid no "
      "share do not stop the family", "femadh/runner/edge_route.py",
      (("                if allowed <= 0:\n", "                if False:\n"),)),
    D("route_landing_resolution_step", "edge route: the jump's resolution the landing step, "
      "not where it landed", "femadh/runner/edge_sweep.py",
      (("Jump(\"retract\", d_fold, d_land, d_land - d_fold, before, after)",
        "Jump(\"retract\", d_fold, d_land, resolution, before, after)"),)),
    D("route_landing_past_separation", "edge route: the jump-out lands past a sweep "
      "separation that lies within the landing's resolution of the fold",
      "femadh/runner/edge_sweep.py",
      (("    d_land = min(d_fold + resolution, min(beyond))",
        "    d_land = d_fold + resolution"),)),
    # -- a smooth law's stalled landing polished from the neighbouring contact edges
    #    (branch landrobust, seeded_defects_landrobust.md)
    D("landrobust_no_smooth_edges", "landing: a smooth law's failed polish is final (no "
      "neighbouring edges)", "femadh/contact/landing.py",
      (("elif not (st.converged and st.stable) and SMOOTH_EDGES:", "elif False:"),)),
    D("landrobust_skips_nearest", "landing, smooth edges: the nearest shifts (1 node) skipped",
      "femadh/contact/landing.py",
      (("for k in range(1, max(far, EDGE_SCAN) + 1 if EDGE_SHIFTS else 1):",
        "for k in range(2, max(far, EDGE_SCAN) + 1 if EDGE_SHIFTS else 1):"),)),
    D("landrobust_join_gap_kept", "landing, smooth edges: a joining node starts at its own "
      "gap (not the contact's)", "femadh/contact/landing.py",
      (("w0[m:m + k] = b[m:m + k] - h[m - 1]", "w0[m:m + k] = w[m:m + k]"),)),
    D("landrobust_contact_sign", "landing, smooth edges: the contact set taken where dP/dh < 0",
      "femadh/contact/landing.py",
      (("return (np.diag(J) if np.ndim(J) == 2 else np.asarray(J)) > 0",
        "return (np.diag(J) if np.ndim(J) == 2 else np.asarray(J)) < 0"),)),
    # -- the far-field factor 2F1(1/2, 1/2; 2; m) by the AGM and the elliptic integrals
    #    (branch greenop, seeded_defects_greenop.md)
    D("greenop_agm_c", "AGM: c_n+1 = c_n^2 / (2 a_n+1), not / (4 a_n+1)",
      "femadh/elastic/green.py",
      (("c = c * c / (4.0 * a_next)", "c = c * c / (2.0 * a_next)"),)),
    D("greenop_agm_weight", "AGM: the sum's weights 4^(n-1), not 2^(n-1)",
      "femadh/elastic/green.py", (("weight *= 2.0", "weight *= 4.0"),)),
    D("greenop_agm_first_c", "AGM: c_1 = (1 - k')/4, not (1 - k')/2",
      "femadh/elastic/green.py",
      (("c = ml / (2.0 * (1.0 + kp))", "c = ml / (4.0 * (1.0 + kp))"),)),
    D("greenop_agm_steps", "AGM: two steps after the first (c_3 ~ 1e-5 left at m = 0.5)",
      "femadh/elastic/green.py", (("AGM_STEPS = 4", "AGM_STEPS = 2"),)),
    D("greenop_split_low", "elliptic form from m = 0.02 (its cancellation ~4/m ulps)",
      "femadh/elastic/green.py", (("AGM_SPLIT = 0.5", "AGM_SPLIT = 0.02"),)),
    D("greenop_agm_sum", "AGM: the factor (1 - S/m)/a_N, not (1 - 2S/m)/a_N",
      "femadh/elastic/green.py",
      (("out[low] = (1.0 - 2.0 * s / ml) / a", "out[low] = (1.0 - s / ml) / a"),)),
    D("greenop_m_zero", "AGM: m = 0 divides 0 by 0 (no floor at the smallest normal)",
      "femadh/elastic/green.py",
      (("ml = np.maximum(m[low], np.finfo(float).tiny)", "ml = m[low]"),)),
    D("greenop_elliptic_branch", "elliptic branch: E - m K, not E - (1-m) K",
      "femadh/elastic/green.py",
      (("(special.ellipe(mh) - (1.0 - mh) * special.ellipk(mh))",
        "(special.ellipe(mh) - mh * special.ellipk(mh))"),)),
    # -- the AGM kernel and getri re-applied (branch landdet, seeded_defects_landdet.md)
    D("landdet_agm_everywhere", "far-field factor: the AGM up to the disk edge (its 4 steps "
      "do not converge as k' -> 0)", "femadh/elastic/green.py",
      (("AGM_SPLIT = 0.5", "AGM_SPLIT = 1.0"),)),
    D("landdet_branches_swapped", "far-field factor: the AGM above the split, E - (1-m)K "
      "below it", "femadh/elastic/green.py",
      (("    low = m < AGM_SPLIT\n", "    low = m >= AGM_SPLIT\n"),)),
    D("landdet_elliptic_prefactor", "far-field factor, elliptic branch: 2 / (pi m), not "
      "4 / (pi m)", "femadh/elastic/green.py",
      (("out[~low] = 4.0 / (math.pi * mh)", "out[~low] = 2.0 / (math.pi * mh)"),)),
    D("landdet_elliptic_k_sign", "far-field factor, elliptic branch: E + (1-m)K",
      "femadh/elastic/green.py",
      (("(special.ellipe(mh) - (1.0 - mh) * special.ellipk(mh))",
        "(special.ellipe(mh) + (1.0 - mh) * special.ellipk(mh))"),)),
    D("landdet_getri_transposed", "K = C^-T by getri (the compliance is not symmetric)",
      "femadh/elastic/operator.py",
      (("linalg.inv(self.compliance, check_finite=False)",
        "linalg.inv(self.compliance.T, check_finite=False)"),)),
    # -- the landing's Cholesky and relaxation LU by LAPACK directly (coordinator, session 11)
    D("cho_lower", "direct potrf: the lower factor with potrs told upper",
      "femadh/contact/linalg.py",
      (("c, info = _POTRF(a, lower=False, overwrite_a=overwrite_a, clean=False)",
        "c, info = _POTRF(a, lower=True, overwrite_a=overwrite_a, clean=False)"),)),
    D("cho_indefinite_silent", "direct potrf: an indefinite matrix not refused (the descent "
      "takes a step of a partial factor instead of raising its damping)",
      "femadh/contact/linalg.py",
      (("    if info > 0:\n        raise linalg.LinAlgError(f\"{info}-th leading minor",
        "    if info > 999999:\n        raise linalg.LinAlgError(f\"{info}-th leading minor"),)),
    D("krylov_banded_law_sign", "Newton-Krylov with a sub-grid law: its tridiagonal "
      "Jacobian entered with the wrong sign in GMRES's product",
      "femadh/contact/complementarity.py",
      (("            return a * (product(v) + apply_jacobian(D, fr, v))",
        "            return a * (product(v) - apply_jacobian(D, fr, v))"),)),
    D("study_reuses_other_code", "study: a point computed by other femadh code reused "
      "(its record's code fingerprint not compared)", "femadh/studies/sweep.py",
      (("        other = {k for k, r in done.items() if r.get(\"femadh\") != code_id()}",
        "        other = set()"),)),
    D("lifecycle_running_signal_unhandled", "lifecycle: a signal while the 'running' "
      "summary is written escapes the block before it runs (generator didn't yield)",
      "femadh/runner/lifecycle.py",
      (("                except Interrupted:\n                    # a signal while the",
        "                except ImportError:\n                    # a signal while the"),)),
    D("gmres_strided_norm", "GMRES: |b| of a strided b as sqrt(b . b) (not norm's bits)",
      "femadh/contact/linalg.py", (("    b = np.ascontiguousarray(b)\n", ""),)),
    D("lu_empty_direct", "direct getrf on an empty system (its size read as an illegal "
      "argument: ValueError where scipy returns empty factors)", "femadh/contact/linalg.py",
      (("a.ndim == ndim and a.size > 0", "a.ndim == ndim"),)),
    # -- which landing fallback lands (branch landfix, seeded_defects_landfix.md)
    D("landfix_no_next_edges", "landing: a relaxation without a polished state is final "
      "(no neighbouring edges after it)", "femadh/contact/landing.py",
      (("    near = _next_edges(problem, d, w, active, tol=tol, max_iter=max_iter)",
        "    near = None"),)),
    D("landfix_relaxed_unpolished", "landing: the relaxed state taken though its polish "
      "did not converge on a stable state", "femadh/contact/landing.py",
      (("        if out.converged and out.stable:", "        if True:"),)),
    D("landfix_relax_set_unsettled", "landing relaxation: stops on the residual alone, its "
      "contact set still changing", "femadh/contact/landing.py",
      (("if r <= tol and np.array_equal(new_A, A):", "if r <= tol:"),)),
    D("landfix_relaxed_descent_set", "landing: the relaxed state polished from the descent's "
      "contact set, not its own", "femadh/contact/landing.py",
      (("max_iter=max_iter, active0=ar)", "max_iter=max_iter, active0=active)"),)),
    # -- the relaxation's damping referred to each contact set's first residual (branch
    #    relaxfix, seeded_defects_relaxfix.md)
    D("relaxfix_ref_not_reset", "landing relaxation: the damping's reference residual kept "
      "from the first step, not reset when the contact set changes", "femadh/contact/landing.py",
      (("if A_set is None or not np.array_equal(A, A_set):", "if A_set is None:"),)),
    # (relaxfix_no_ceiling retired: with the reference the running largest residual,
    # r / r_set <= 1 and the ceiling cannot act - the mutant was equivalent)
    D("relaxfix_first_residual", "landing relaxation: the damping referred to each set's first "
      "residual, not its running largest (a set entered at a small residual that then rises "
      "keeps mu at RELAX_MU0)", "femadh/contact/landing.py",
      (("        r_set = max(r_set, r)\n", ""),)),
    D("relaxfix_ref_every_step", "landing relaxation: the reference residual renewed every "
      "step (the damping stays RELAX_MU0, never Newton's)", "femadh/contact/landing.py",
      (("if A_set is None or not np.array_equal(A, A_set):", "if True:"),)),
    # -- SIGTERM while the femadh program starts (branch startup)
    D("startup_sigterm_default", "the program's SIGTERM while it starts is the default (a "
      "silent death, exit -15)", "femadh/cli.py",
      (("if _as_program() and signal.getsignal(signal.SIGTERM) is signal.SIG_DFL:",
        "if False:"),)),
    D("startup_sigterm_exits_in_main", "SIGTERM inside main's guard ends the process at once "
      "(a study's claimed folder keeps its lock file)", "femadh/cli.py",
      (("            signal.signal(signal.SIGTERM, raise_terminated)",
        "            signal.signal(signal.SIGTERM, _stop_at_once)"),)),
    D("startup_handler_in_workers", "a worker spawned by the femadh script takes the "
      "program's start-up handlers (an idle worker's SIGTERM: exit 143 and a line)",
      "femadh/cli.py",
      (('            and (mp is None or (mp.current_process().name == "MainProcess"',
        '            and (True or (mp.current_process().name == "MainProcess"'),)),
    D("startup_worker_keeps_handler", "the workers' set-up leaves a start-up SIGTERM handler "
      "in place", "femadh/studies/executors.py",
      (("            signal.signal(signal.SIGTERM, signal.SIG_DFL)\n",
        "            pass\n"),)),
    D("startup_main_sigterm_default", "python -m femadh: SIGTERM while femadh.cli is imported "
      "is the default (a silent death)", "femadh/__main__.py",
      (("if _ours:\n    signal.signal(signal.SIGTERM, _sigterm_while_importing)",
        "if False:\n    signal.signal(signal.SIGTERM, _sigterm_while_importing)"),)),
    # -- a signal while a run folder is claimed (review of this session)
    D("folder_claim_signal_keeps_lock", "run folder: a signal while the folder is claimed "
      "leaves its lock file", "femadh/io/run_folder.py",
      (("        except BaseException:\n            # a refusal, or a signal",
        "        except OutputError:\n            # a refusal, or a signal"),)),
    D("defer_late_signal_lost", "deferred estimate: a signal after the completion's last "
      "safe point is lost (the run ends as if unsent)", "femadh/runner/estimates.py",
      (("        interrupt.check()\n    except Interrupted as exc:\n        res.stop(exc)\n"
        "        if not done:",
        "        pass\n    except Interrupted as exc:\n        res.stop(exc)\n"
        "        if not done:"),)),
    D("defer_abandon_keeps_grid", "deferred estimate abandoned: the judged part's member "
      "record left in a stopped run's grid record", "femadh/runner/estimates.py",
      (("        res.grid.clear()\n        res.grid.update(grid0)\n        res.estimates = {}\n",
        "        res.estimates = {}\n"),)),
    D("study_late_signal_lost", "study: a signal whose stop found every point finished is "
      "lost (exit 0)", "femadh/studies/sweep.py",
      (("                if stop:\n                    # a signal whose stop found",
        "                if False:\n                    # a signal whose stop found"),)),
    D("study_stale_tmp_kept", "study: a killed worker's temporary file left in its point's "
      "folder for good", "femadh/studies/sweep.py",
      (("        _remove_stale_temporaries(out)\n", ""),)),
    D("defer_bug_draws_figures", "adaptive loop: a run whose deferred completion hit a bug "
      "still draws its figures", "femadh/runner/adaptive.py",
      (("            if figures and raised is None and ", "            if figures and "),)),
    D("study_no_figures_ignored", "study: --no-figures ignored (study.png drawn anyway)",
      "femadh/studies/sweep.py",
      (("        result.figure = (study_figure(points, result.records, out, quantity) if figures\n",
        "        result.figure = (study_figure(points, result.records, out, quantity) if True\n"),)),
    D("resume_folds_not_loaded", "resume: the fold records not restored from the checkpoint "
      "(the members trace the grid steps for their folds: the jump and hysteresis errors "
      "move)", "femadh/runner/sink.py",
      (("                      if (b, df, dl) in kept]\n", "                      if False]\n"),)),
    D("report_stopped_not_met", "report: a stopped run's accuracy printed as NOT met (a "
      "verdict it has not made)", "femadh/runner/report.py",
      (("        return (f\"not assessed ({res.status})\" if stopped and not a[\"met\"]",
        "        return (f\"not assessed ({res.status})\" if False and not a[\"met\"]"),)),
    D("study_vary_error_on_file", "study: a --vary value's error named against the scene "
      "file", "femadh/studies/sweep.py",
      (("    where = (lambda key: f\"{source} {key}\") if source else (scene.path or \"study\")",
        "    where = scene.path or \"study\""),)),
    D("resume_estimate_stop_no_checkpoint", "run: a stop in the peak search or the estimate "
      "leaves no checkpoint (the resumed members re-search their folds)",
      "femadh/runner/contact.py",
      (("        except Interrupted:\n            raise\n        except BaseException:\n"
        "            done()\n            raise\n        done()\n",
        "        except BaseException:\n            done()\n            raise\n        done()\n"),
       ("        res.timings[\"solve_s\"] = time.perf_counter() - t1\n\n",
        "        res.timings[\"solve_s\"] = time.perf_counter() - t1\n        life.on_stop = None\n\n"))),
    D("study_kept_counts_redone", "study stopped: points the next run computes again counted "
      "as kept", "femadh/studies/sweep.py",
      (("                not (finished(r) and r.get(\"femadh\") == code_id() and serves(r, estimate))",
        "                not finished(r)"),)),
    D("study_tmp_under_live_lock", "study: a stale temporary file removed from a point's "
      "folder whose run lock a live worker holds", "femadh/studies/sweep.py",
      (("                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)\n", ""),)),
    D("resume_committed_not_loaded", "resume: the committed states not held in memory (the "
      "estimate's members traced whole: estimates differ from the uninterrupted run's)",
      "femadh/runner/sink.py",
      (("            self.committed.setdefault(b, []).append(snap)\n", ""),)),
    D("folder_lock_signal_keeps_file", "run folder: a signal at the lock leaves the lock file "
      "it created", "femadh/io/run_folder.py",
      (("                _drop_unheld(fd, lock)\n", "                os.close(fd)\n"),)),
    # -- the adaptive loop's deferred estimate completed (review of pace2)
    D("defer_stop_keeps_partial", "adaptive: a stop while the kept trial's deferred estimate "
      "is completed leaves the judged numbers' partial breakdown", "femadh/runner/estimates.py",
      (("        res.stop(exc)\n        if not done:\n            abandon(res.error)\n",
        "        res.stop(exc)\n"),)),
    D("defer_stopped_trial_completed", "adaptive: a kept trial stopped after its estimate has "
      "its deferred rest solved", "femadh/runner/estimates.py",
      (('    if res.status not in ("converged", "failed"):\n        abandon(',
        '    if False:\n        abandon('),)),
    D("defer_bug_unwritten", "adaptive: a bug while completing the kept trial's estimate is "
      "raised before the summary says failed", "femadh/runner/adaptive.py",
      (("            raised = exc\n", "            raise\n"),)),
    D("defer_bug_not_failed", "adaptive: a bug while completing leaves the result converged",
      "femadh/runner/estimates.py",
      (('        res.fail(f"{type(exc).__name__}: {exc}" if str(exc) else type(exc).__name__)\n'
        '        abandon(res.error)\n        raise\n', "        raise\n"),)),
    D("defer_superseded_held", "adaptive: a superseded trial's pending rest (its problem, sink "
      "and member problems) held through the next trial", "femadh/runner/adaptive.py",
      (('            ahead["res"].pending_estimate = None\n', "            pass\n"),)),
    D("defer_completion_untimed", "adaptive: the completion's seconds not in the trial's "
      "estimate_s", "femadh/runner/estimates.py",
      (('        for key in ("estimate_s", "total_s"):\n', '        for key in ():\n'),)),
    D("defer_complete_only_if_met", "adaptive: the deferred estimate completed only where the "
      "kept trial met (a kept missed trial states the partial one)", "femadh/runner/adaptive.py",
      (("    if res is not None:\n        from .estimates import complete_estimate",
        "    if res is not None and out.met:\n        from .estimates import complete_estimate"),)),
    D("defer_met_keeps_partial", "estimate: a deferred estimate that meets its request returns "
      "the judged numbers' breakdown", "femadh/runner/estimates.py",
      (("        return complete()\n    spent", "        return partial\n    spent"),)),
    D("defer_stop_swallowed", "adaptive: a stop while completing the kept trial's estimate "
      "swallowed (the run ends converged)", "femadh/runner/estimates.py",
      (("        res.stop(exc)\n        if not done:\n            abandon(res.error)\n",
        "        pass\n"),)),
    D("defer_rest_fail_uses_judged", "estimate: a member's failed rest falls back on its judged "
      "numbers instead of its whole trace", "femadh/runner/estimates.py",
      (('                if hl_m is None:\n                    r = run(member, progress=False, '
        'estimate="peak")\n                if hl_m is not None:',
        '                if hl_m is None:\n                    hl_m, how = rm.hl, rm.m.solves\n'
        '                if hl_m is not None:'),)),
    D("first_from_plan", "adaptive: a finer request's first member scaled from the plan's "
      "spacing where the trapping cap binds (the old rule)", "femadh/runner/adaptive.py",
      (("            starts.insert(0, min(ref.spacing * scale, top))\n",
        "            starts.insert(0, min(plan.spacing * scale, top))\n"),)),
    D("first_cap_inverted", "adaptive: the capped 1e-3 member's spacing used only where the cap "
      "does not bind", "femadh/runner/adaptive.py",
      (("not follows and ref.spacing < ref.asked:",
        "not follows and ref.spacing >= ref.asked:"),)),
    D("first_scale_squared", "adaptive: the first member's scaling (target / 1e-3)^(2/ORDER)",
      "femadh/runner/adaptive.py",
      (("    scale = (target / REFERENCE_ACCURACY) ** (1.0 / ORDER)\n",
        "    scale = (target / REFERENCE_ACCURACY) ** (2.0 / ORDER)\n"),)),
    # -- resume after a stop while the figures are drawn (femadh/runner/figures.py)
    D("figres_outcome_not_kept", "figures: a run stopped while drawing them keeps no record "
      "of the outcome it had reached (--resume solves it again)", "femadh/runner/figures.py",
      (("    if res.stopped_in_figures is None:\n        res.stopped_in_figures = {",
        "    if False:\n        res.stopped_in_figures = {"),)),
    D("figres_outcome_unwritten", "figures: summary.json of a run stopped in its figures "
      "leaves out the outcome it had reached", "femadh/runner/result.py",
      (('               if getattr(res, "stopped_in_figures", None) is not None else {}),',
        '               if False else {}),'),)),
    D("figres_redraws_all", "figures resume: every figure drawn again, the ones on disk too",
      "femadh/runner/figures.py",
      (("            missing = [n for n in figure_names(res) if not (folder.path / n).exists()]",
        "            missing = figure_names(res)"),)),
    D("figres_status_not_restored", "figures resume: the run's outcome not restored (the "
      "summary keeps the read-back result's own status)", "femadh/runner/figures.py",
      (('        res.status, res.error, res.failure_kind = (outcome.get("status"),\n'
        '                                                   outcome.get("error"),\n'
        '                                                   outcome.get("failure_kind"))\n',
        ''),)),
    D("figres_marker_left", "figures resume: the finished run's summary still names an "
      "outcome pending its figures", "femadh/runner/figures.py",
      (("            data.pop(STOPPED_IN_FIGURES, None)\n        else:",
        "            pass\n        else:"),)),
    D("figres_restop_drops_outcome", "figures resume stopped again: the outcome dropped from "
      "the summary (the next resume solves the run again)", "femadh/runner/figures.py",
      (("            data[STOPPED_IN_FIGURES] = res.stopped_in_figures\n",
        "            data.pop(STOPPED_IN_FIGURES, None)\n"),)),
    D("figres_unchecked_rows", "figures resume: curve.csv rows taken without their checksum "
      "(a changed digit drawn and reported)", "femadh/runner/figures.py",
      (("            if row_problem(line, k, head, n_crc, plan, run_id):\n",
        "            if False:\n"),)),
    D("figres_iters_float", "figures resume: the iteration counts read back as floats",
      "femadh/runner/figures.py",
      (('np.array([int(v) for v in x], dtype=int) if c == "n_iter"',
        'np.array([float(v) for v in x], dtype=float) if c == "n_iter"'),)),
    D("figres_profile_picks", "figures resume: the kept profiles picked over one state less "
      "than the branch's plan", "femadh/runner/figures.py",
      (("[ks[j] for j in sorted(_picks(total.get(b, len(ks)))) if j < len(ks)]",
        "[ks[j] for j in sorted(_picks(total.get(b, len(ks)) - 1)) if j < len(ks)]"),)),
    D("figres_nodes_last_state", "figures resume: the nodes read from a kept profile's state "
      "after the first", "femadh/runner/figures.py",
      (("    res.nodes = fields[0][1]\n", "    res.nodes = fields[max(fields)][1][::-1]\n"),)),
    D("cz_width_no_m1", "adaptive: the cohesive zone's width m a instead of (m - 1) a",
      "femadh/runner/adaptive.py",
      (("    return lam, (m - 1.0) * a * maugis_length_units(",
        "    return lam, m * a * maugis_length_units("),)),
    D("cz_lambda_no_2", "adaptive: Maugis' lambda without its factor 2",
      "femadh/runner/adaptive.py",
      (("    lam = 2.0 * sigma0 * (scene.sphere.radius / (math.pi * w_lj * k * k)) ** (1.0 / 3.0)",
        "    lam = sigma0 * (scene.sphere.radius / (math.pi * w_lj * k * k)) ** (1.0 / 3.0)"),)),
    D("cz_k_estar", "adaptive: the zone's K = E* instead of 4 E* / 3",
      "femadh/runner/adaptive.py",
      (("    k = 4.0 * scene.e_star / 3.0\n    lam = 2.0", "    k = scene.e_star\n    lam = 2.0"),)),
    D("cz_share_ignored", "adaptive: the cohesive zone's spacing not scaled by the LJ share "
      "of the work of adhesion", "femadh/runner/adaptive.py",
      (("(target / (REFERENCE_ACCURACY * share))", "(target / REFERENCE_ACCURACY)"),)),
    D("cz_target_unscaled", "adaptive: the cohesive zone's spacing the same for every request",
      "femadh/runner/adaptive.py",
      (("    return zone[1] / CZ_NODES * (target / (REFERENCE_ACCURACY * share)) ** (1 / FIRST_ORDER)",
        "    return zone[1] / CZ_NODES * (1 / share) ** (1 / FIRST_ORDER)"),)),
    D("cz_also_loose", "adaptive: the cohesive zone's start applied to looser requests too",
      "femadh/runner/adaptive.py",
      (("    if target > REFERENCE_ACCURACY:\n        return None\n    hz = cohesive_spacing",
        "    if False:\n        return None\n    hz = cohesive_spacing"),)),
    D("cz_pulloff_state_max", "maugis: the pull-off state at the largest P, not the least",
      "femadh/reference/maugis.py",
      (("    x, P = _refined_min(P_of_logm, _LOG_M1, P_of_logm(_LOG_M1))\n",
        "    x, P = _refined_min(lambda x: -P_of_logm(x), _LOG_M1, -P_of_logm(_LOG_M1))\n    P = -P\n"),)),
    # -- the landing descent's single-precision factor and double conjugate gradients
    # (femadh/contact/landing.py _Damped, femadh/contact/linalg.py pcg, cho_factor_single)
    D("landfast_cg_undamped", "landing descent: the iterations solve the undamped Hessian "
      "(the damping left out of the product)", "femadh/contact/landing.py",
      (("return (blas.dsymv(1.0, H.T, v[::-1], lower=1) + damp * v[::-1])[::-1]",
        "return blas.dsymv(1.0, H.T, v[::-1], lower=1)[::-1]"),)),
    D("landfast_rtol_loose", "landing descent: the iterations stop at a relative residual "
      "of 1e-3", "femadh/contact/landing.py", (("SINGLE_RTOL = 1e-13", "SINGLE_RTOL = 1e-3"),)),
    D("landfast_factor_undamped", "landing descent: the single factor (and its positive-"
      "definiteness test) of the undamped Hessian", "femadh/contact/landing.py",
      (("u = cho_factor_single(H[::-1, ::-1], (np.diagonal(H) + damp)[::-1])",
        "u = cho_factor_single(H[::-1, ::-1], np.diagonal(H)[::-1])"),)),
    D("landfast_curvature_ignored", "pcg: a direction of negative curvature taken as any other "
      "(an indefinite damped Hessian solved as if positive definite)",
      "femadh/contact/linalg.py",
      (('        if not pq > 0:\n            return x, k, "curvature"',
        '        if not pq != 0:\n            return x, k, "curvature"'),)),
    D("landfast_descent_check", "landing descent: the descent-direction check inverted "
      "(grad . dw > 0 taken)", "femadh/contact/landing.py",
      (('ok = status == "converged" and rev @ x > 0 and np.all(np.isfinite(x))',
        'ok = status == "converged" and rev @ x < 0 and np.all(np.isfinite(x))'),)),
    D("landfast_rhs_order", "landing descent: the gradient not reversed into the factor's "
      "node order", "femadh/contact/landing.py", (("rev = rhs[::-1]", "rev = rhs"),)),
    D("landfast_whole_descent_single", "landing descent: the whole descent (lattice-trapped "
      "grids, the retry after a failed polish) also by the single factor",
      "femadh/contact/landing.py",
      (("single = roundoff and H.shape[0] >= SINGLE_MIN_NODES",
        "single = H.shape[0] >= SINGLE_MIN_NODES"),)),
    D("landfast_factor_diagonal", "single factor: the damped diagonal not written (the "
      "factor of H + its own diagonal again)", "femadh/contact/linalg.py",
      (("        d[...] = diag                       # the damped diagonal, formed in double",
        "        d += diag"),)),
    D("first_no_fallback", "adaptive: a first member the node budget refuses ends the request "
      "(no fall back to the coarser start)", "femadh/runner/adaptive.py",
      (("        if tr.operator is not None:\n            return tr\n    return tr",
        "        return tr\n    return tr"),)),
    D("first_zone_on_follow", "adaptive: the cohesive zone's start kept on a band following "
      "the edge", "femadh/runner/adaptive.py",
      (("        if tr.follow is not None and h != starts[-1]:", "        if False:"),)),
    D("cz_on_closure", "adaptive: the cohesive zone's start on the Hertz closure model too",
      "femadh/runner/adaptive.py",
      (('    if gap is None or getattr(gap, "contact_model", "complementarity") != "complementarity":\n        return None\n    lj = _lj_laws',
        '    if gap is None:\n        return None\n    lj = _lj_laws'),)),
    D("figres_trial_level", "figures resume: a loop's trial reads back the user's folder "
      "(it may hold another trial's run)", "femadh/runner/contact.py",
      (("resume_from is None and (\n            folder_id is None or folder_id == scene_id(scene)):",
        "resume_from is None and (\n            True):"),)),
    D("figres_estimate_ignored", "figures resume: a resume asking for the estimate reads back a "
      "run made without one", "femadh/runner/figures.py",
      (('            estimate is True and not prev.get("error_estimates")):',
        '            False):'),)),
    D("figres_fields_unchecked", "figures resume: fields.csv's states taken without checking "
      "them against curve.csv and the grid", "femadh/runner/figures.py",
      (('        if float(rows[k][i_d]) != d or len({a.size for a in arrs}) != 1:\n            return None\n    if fields[0][1].size != (prev.get("grid") or {}).get("nodes"):\n        return None\n',
        ''),)),
    D("trap_auto_ignores_trap", "edge route: 'auto' pilots only where the grid follows the "
      "edge (a static band trapped at its edge keeps the sweep)", "femadh/runner/edge_route.py",
      (("    if route == \"auto\" and not (follows or (\n",
        "    if route == \"auto\" and not (follows or False and (\n"),)),
    D("trap_static_measure", "edge route: the trap ratio against the static cap's softening "
      "(the larger of LJ and the step) instead of their sum", "femadh/runner/edge_route.py",
      (("    from ..discretisation.plan import follow_safe_spacing\n",
        "    from ..discretisation.plan import safe_spacing as follow_safe_spacing\n"),)),
    D("trap_uncapped_spacing", "edge route: the trap ratio inverted (safe spacing over the "
      "member's)", "femadh/runner/edge_route.py",
      (("    return member.spacing / follow_safe_spacing(problem)",
        "    return follow_safe_spacing(problem) / member.spacing"),)),
    D("trap_no_margin", "edge route: 'auto' pilots at any trap ratio above 1 (no margin)",
      "femadh/runner/edge_route.py",
      (("            and edge_trap_ratio(scene, member()) > EDGE_TRAP_MARGIN)):",
        "            and edge_trap_ratio(scene, member()) > 1.0)):"),)),
    D("trap_every_law", "edge route: the trap ratio measured on a scene without a sub-grid "
      "step too", "femadh/runner/edge_route.py",
      (("    return scene.gap is not None and any(getattr(law, \"SUBGRID\", False)\n",
        "    return scene.gap is not None and (True or any(getattr(law, \"SUBGRID\", False)\n"),
       ("                                         for law in scene.effects.values())\n",
        "                                         for law in scene.effects.values()))\n"))),
    D("cli_broken_pipe_bug", "cli: a reader that goes away is reported as an internal error",
      "femadh/cli.py",
      (("    except BrokenPipeError:\n", "    except ZeroDivisionError:\n"),)),
    D("landfast_spotrf_notpd", "landing: a failed single-precision factorisation refuses the "
      "trial as not positive definite (a matrix only beyond single precision's condition)",
      "femadh/contact/landing.py",
      (("            # factorisation decides, as it did before this path\n            return None\n",
        "            # factorisation decides, as it did before this path\n            return self.NOT_PD\n"),)),
    D("pcg_breakdown_as_curvature", "pcg: a preconditioner's breakdown reported as curvature",
      "femadh/contact/linalg.py",
      (('        if not rz > 0:\n            return x, k, "breakdown"',
        '        if not rz > 0:\n            return x, k, "curvature"'),)),
    D("solve_single_unscaled", "cho_solve_single: the residual cast to single precision "
      "unscaled (a tiny residual vanishes)", "femadh/contact/linalg.py",
      (("    y = blas.strsv(u, (r / scale).astype(np.float32), trans=1)",
        "    y = blas.strsv(u, r.astype(np.float32), trans=1)"),
       ("    return y.astype(float) * scale\n", "    return y.astype(float)\n"))),
    D("trap_ratio_request", "edge route: the trap ratio read on the request's own first member "
      "(a finer request reads below the margin)", "femadh/runner/adaptive.py",
      (("                                              else reference_trial(scene))))",
        "                                              else first)))"),)),
    D("check_first_unrefused", "check: an adaptive request whose first member exceeds the node "
      "budget passes the check", "femadh/scene/resources.py",
      (("        if first_nodes[1] > BANDED_MAX_NODES:", "        if False:"),)),
    D("check_first_fixed_300", "check: an adaptive scene's time estimated on 300 nodes whatever "
      "its plan", "femadh/scene/resources.py",
      (("            n = first_nodes or 300", "            n = 300"),)),
    D("decay_bound_off", "Richardson: a monotone triple extrapolated from its finest difference "
      "alone, however fast it fell (the coarser difference's bound dropped)",
      "femadh/estimate/richardson.py",
      (("                d1 = math.copysign(max(abs(d1), abs(d2) * _implied(decay_order, "
        "ratio,\n", "                d1 = math.copysign(max(abs(d1), 0.0 * _implied(decay_order, "
        "ratio,\n"),)),
    D("decay_order_3", "Richardson: the coarser difference's bound taken at third order",
      "femadh/estimate/richardson.py",
      (("DECAY_ORDER = 2.0\n", "DECAY_ORDER = 3.0\n"),)),
    D("decay_uneven_even", "Richardson: the coarser difference of uneven members scaled as if "
      "even", "femadh/estimate/richardson.py",
      (("    if ratio2 is None or ratio2 == ratio:\n        return ratio**-p",
        "    if True:\n        return ratio**-p"),)),
    D("decay_no_sigma_gate", "estimate: the coarser difference bounds the finest without a "
      "sigma-gap too (a smooth number converging faster than second order over-estimated)",
      "femadh/runner/estimates.py",
      (("    if problem.sigma is None:\n        return None\n    return DECAY_ORDER",
        "    return DECAY_ORDER"),)),
    D("decay_no_trap_gate", "estimate: the coarser difference bounds the finest however near "
      "a node's stiffness the coarsest member softens", "femadh/runner/estimates.py",
      (("    return DECAY_ORDER if member_safe(problem, spread) else None\n",
        "    return DECAY_ORDER\n"),)),
    D("decay_off", "estimate: the finest difference always read alone (the chance-small "
      "difference under-reads)", "femadh/runner/estimates.py",
      (("    return DECAY_ORDER if member_safe(problem, spread) else None\n",
        "    return None\n"),)),
    D("decay_locked_dropped", "estimate: the deepest state's placed members without the bound",
      "femadh/runner/estimates.py",
      (("                                       decay_order=decay_order(problem, h2 / h0)).items():",
        "                                       ).items():"),)),
    D("regrid_budget_internal", "tracing: a band regrid past the node budget escapes as an "
      "internal error (exit 1) instead of a failed trial", "femadh/runner/tracing.py",
      (("    except NodeBudgetError as exc:\n        # the band grew",
        "    except ZeroDivisionError as exc:\n        # the band grew"),)),
    D("budget_failure_refined", "adaptive: a band's node-budget failure refines h (futile: "
      "a finer member needs more)", "femadh/runner/adaptive.py",
      (('        if res.failure_kind == "budget":\n', '        if False:\n'),)),
    # -- newcomer trial (ux14): where a bad value came from, what a resume refusal names, the
    # estimate as one phase of the progress line
    D("ux14_replace_error_on_file", "Scene.replace: a value given to the call reported "
      "against the scene file", "femadh/scene/__init__.py",
      (("        raise given_by(exc, where, changes) from None", "        raise exc from None"),)),
    D("ux14_replace_error_every_line_on_call", "Scene.replace: every error line named against "
      "the call, a value the file holds too", "femadh/errors.py",
      (("        return isinstance(key, str) and any(key == k or key.startswith(k + \".\") for k "
        "in keys)", "        return True"),)),
    D("ux14_resume_refusal_no_keys", "resume of a changed scene: the refusal names no key "
      "(as before)", "femadh/io/run_folder.py",
      (("        if old is None or self.given is None:", "        if True:"),)),
    D("ux14_resume_keys_undotted", "resume of a changed scene: a key named without its tables",
      "femadh/io/run_folder.py",
      (("            out += changed_keys(old.get(k, _UNSET), new.get(k, _UNSET), f\"{prefix}{k}.\")",
        "            out += changed_keys(old.get(k, _UNSET), new.get(k, _UNSET), f\"{k}.\")"),)),
    D("ux14_resume_trial_keys", "resume of a changed adaptive scene: the folder records its "
      "trial's keys (its grid, its radius) as the user's", "femadh/runner/estimates.py",
      (("    out.given = scene.as_given          # (its run folder is the user's scene's)\n", ""),)),
    D("ux14_estimate_not_one_phase", "progress: the estimate's members shown as parts of the "
      "grid's phase (no estimate phase of their own)", "femadh/runner/contact.py",
      (("            with deferring(None), phase(\"estimate\"):", "            with deferring(None):"),)),
    D("ux14_estimate_judged_pass_shown", "progress: the members' judged numbers at hand shown "
      "as a pass through the members again", "femadh/runner/estimates.py",
      (("                if not judged_only:\n                    # (the judged numbers alone",
        "                if True:\n                    # (the judged numbers alone"),)),
    # -- newcomer trial, session 14 (ux14b): a value to its error's place, abbreviations
    #    refused, a refused resume leaves no folder, a finished folder not advised --resume,
    #    a unit in the wrong case named
    D("ux14b_value_five_digits", "a value printed to five digits whatever its error (-1.602 "
      "± 5e-07 mN)", "femadh/io/plots.py",
      (('        txt = f"{r:.{max(-place, 0)}f}"', '        txt = f"{v:.5g}"'),)),
    D("ux14b_place_of_unrounded_error", "the value's place taken from the unrounded error "
      "(0.0096: 0.988 ± 0.01)", "femadh/io/plots.py",
      (('    e = float(f"{abs(err):.1g}")', '    e = abs(err)'),)),
    D("ux14b_negative_zero", "a value below half the error's digit printed as -0.0 or its "
      "own digits", "femadh/io/plots.py",
      (("    if abs(v) < 0.5 * 10.0 ** place:\n", "    if False:\n"),)),
    D("ux14b_instrument_four_decimals", "the instrument's z and d to four decimals whatever "
      "their error", "femadh/runner/report.py",
      (('        return f"{_pm(v, e * 1e9, 8)} nm" if e is not None else f"{v:.4f} nm"',
        '        return f"{v:.4f} ± {e * 1e9:.1g} nm" if e is not None else f"{v:.4f} nm"'),)),
    D("ux14b_meniscus_five_digits", "paper 2's F printed to five digits (60.227 ± 6e-07 nN)",
      "femadh/runner/meniscus.py",
      (('        F = f"F = {value_error_text(f[k] * s, err * s if estimated else None)} {unit}"',
        '        F = f"F = {f[k] * s:.5g}" + (f" ± {err * s:.1g}" if estimated else "") + '
        'f" {unit}"'),)),
    D("ux14b_regime_four_decimals", "the regime table's pull-off to four decimals whatever "
      "its error", "femadh/studies/regime.py",
      (("        return value_error_text(v, e)", '        return f"{v:.4f} ± {e:.1g}"'),)),
    D("ux14b_run_abbreviations", "femadh run takes --overwrit for --overwrite",
      "femadh/cli.py",
      (('    r = sub.add_parser("run", allow_abbrev=False,',
        '    r = sub.add_parser("run", allow_abbrev=True,'),)),
    D("ux14b_program_abbreviations", "femadh takes --vers for --version", "femadh/cli.py",
      (('        prog="femadh", allow_abbrev=False,', '        prog="femadh",'),)),
    D("ux14b_sweep_abbreviations", "femadh study sweep takes --work for --workers",
      "femadh/cli.py",
      (('    sw = ss.add_parser("sweep", allow_abbrev=False,',
        '    sw = ss.add_parser("sweep", allow_abbrev=True,'),)),
    D("ux14b_topography_abbreviations", "femadh topography takes --cut for --cutoff",
      "femadh/cli_topography.py",
      (('        "topography", allow_abbrev=False,', '        "topography",'),)),
    D("ux14b_refused_claim_keeps_folder", "a refused --resume leaves the folder it created",
      "femadh/io/run_folder.py",
      (("                    q.rmdir()               # (an empty folder only)",
        "                    break"),)),
    D("ux14b_refused_claim_removes_existing", "a refused --resume removes an empty folder it "
      "did not create", "femadh/io/run_folder.py",
      (("                    created.insert(0, q)\n                except FileExistsError:\n"
        "                    if not q.is_dir():\n                        raise\n",
        "                    created.insert(0, q)\n                except FileExistsError:\n"
        "                    created.insert(0, q)\n"),)),
    D("ux14b_finished_advised_resume", "a finished run's folder refused with 'use --resume'",
      "femadh/io/run_folder.py",
      (("        if _finished(prev):\n            # (--resume would only be refused",
        "        if False:\n            # (--resume would only be refused"),)),
    D("study_stop_no_way_on", "study stopped by a signal: the line says neither to run the "
      "same again nor that none is left", "femadh/cli.py",
      (('               + (f"run the same command again to compute the other {left}" if left else',
        '               + ("" if left else'),)),
    D("max_adhesion_d_four_digits", "the largest adhesion's separation printed to four "
      "digits whatever its error (1.134 nm, known to 0.01)", "femadh/io/plots.py",
      (("    d = value_error_text(hl[\"d_at_max_adhesion_m\"] * 1e9, None if e_d is None else "
        "e_d * 1e9,\n", "    d = value_error_text(hl[\"d_at_max_adhesion_m\"] * 1e9, None if True "
        "else e_d * 1e9,\n"),)),
    D("worker_term_raises_in_import", "figure worker: a SIGTERM while it imports raises "
      "SystemExit there (exit 1; half-built objects' __del__ tracebacks on the run's stderr)",
      "femadh/runner/figures.py",
      (("    # tracebacks on the run's stderr (a stop caught in the suite: pyparsing's Forward)\n"
        "    os._exit(0)\n",
        "    # tracebacks on the run's stderr (a stop caught in the suite: pyparsing's Forward)\n"
        "    raise SystemExit(0)\n"),)),
    D("value_text_unrounded_form", "value ± error: the e-form's digits from the unrounded "
      "value (9.99996e6 ± 100 printed a digit short)", "femadh/io/plots.py",
      (("    r = round(v, -place)\n", "    r = v\n"),)),
    D("ux14b_unit_has_units_of", "'2 MM' for a length: 'but it has units of MM'",
      "femadh/units.py",
      (("        if hint or not (mag is not None and unit):", "        if True:"),)),
    D("ux14b_unit_case_twin_megametre", "'2 MM' suggests the megametre 'Mm' (the table's "
      "order) before 'mm'", "femadh/units.py",
      (("    twins = [low] + [u for u in _FAST if u.lower() == low and u != low]",
        "    twins = [u for u in _FAST if u.lower() == low and u != low] + [low]"),)),
    D("ux14b_unknown_unit_pint_words", "'2 NM': pint's 'could not parse' instead of 'not a "
      "recognised unit'", "femadh/units.py",
      (('type(exc).__name__ == "UndefinedUnitError":', 'type(exc).__name__ == "Undefined":'),)),
]


def _copy_repo(dst):
    for name in ("femadh", "tests", "validation", "meshes"):
        shutil.copytree(ROOT / name, dst / name,
                        ignore=shutil.ignore_patterns("__pycache__", "results", "*.png"))
    (dst / "validation" / "results").mkdir(exist_ok=True)
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, dst / name)


def _apply(root, defect):
    path = root / defect.path
    text = path.read_text()
    for old, new in defect.edits:
        if text.count(old) != 1:
            return None, f"not applied: {old[:50]!r} occurs {text.count(old)} times"
        text = text.replace(old, new)
    original = path.read_text()
    path.write_text(text)
    return original, None


def _first_failure(output):
    m = re.search(r"^(?:FAILED|ERROR) (\S+)", output, re.M)
    if m:
        return m.group(1)
    m = re.search(r"^_+ (?:ERROR collecting )?(\S+) _+$", output, re.M)
    return m.group(1) if m else None


#: the fast subset first (tests not marked slow); the slow physics checks only if it passed
STAGES = (("-m", "not slow"), ("-m", "slow"))
#: pytest's exit code when a stage selects no test (not a failure)
NO_TESTS = 5


def _run_tests(root, tests=()):
    """The stages of pytest -x on the copy at ``root``: (exit code or "timeout", output,
    seconds)."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", MPLBACKEND="Agg", PYTHONDONTWRITEBYTECODE="1",
               FEMADH_SEEDED_DEFECT="1")
    t0 = time.perf_counter()
    text, code = "", 0
    try:
        for stage in STAGES:
            left = TIMEOUT_S - (time.perf_counter() - t0)
            out = subprocess.run([sys.executable, "-m", "pytest", "-x", "-q", "-p",
                                  "no:cacheprovider", "-W", "ignore", *stage, *tests],
                                 cwd=root, env=env, capture_output=True, text=True,
                                 timeout=max(left, 1.0))
            text, code = out.stdout + out.stderr, out.returncode
            if code not in (0, NO_TESTS):
                break
            code = 0
    except subprocess.TimeoutExpired:
        text, code = "", "timeout"
    return code, text, time.perf_counter() - t0


def run_one(defect, root, tests=()):
    original, problem = _apply(root, defect)
    if problem:
        return {"defect": defect, "caught": None, "test": problem, "seconds": 0.0}
    code, text, dt = _run_tests(root, tests)
    (root / defect.path).write_text(original)
    if code == "timeout":
        return {"defect": defect, "caught": False, "test": f"suite hung > {TIMEOUT_S} s",
                "seconds": dt}
    caught = code != 0
    return {"defect": defect, "caught": caught,
            "test": (_first_failure(text) or f"exit {code}") if caught else "(suite passed)",
            "seconds": dt}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", help="run the defects whose name contains this (several: "
                    "comma-separated); the report then goes to seeded_defects_partial.md")
    ap.add_argument("--jobs", type=int, default=2, help="suites in parallel (default 2)")
    ap.add_argument("--list", action="store_true", help="list the defects and exit")
    ap.add_argument("--no-report", action="store_true", help="do not write the report")
    ap.add_argument("--report", help="write the report to this file (default: "
                    "validation/results/seeded_defects.md, or seeded_defects_partial.md "
                    "with --only)")
    ap.add_argument("--tests", nargs="+", default=(), metavar="PATH",
                    help="run only these test files on each defect (a quick check of new "
                         "code; a defect they catch is caught by the whole suite too)")
    ap.add_argument("--no-clean-check", action="store_true",
                    help="do not run the tests on the unmodified tree first")
    args = ap.parse_args(argv)
    missing = [t for t in args.tests if not (ROOT / t.split("::")[0]).exists()]
    if missing:
        # pytest's usage error would read as "suite passed": every defect reported missed
        ap.error(f"--tests: no such test file {', '.join(missing)}")
    wanted = [w for w in (args.only or "").split(",") if w]
    todo = [d for d in DEFECTS if not wanted or any(w in d.name for w in wanted)]
    if args.list:
        for d in todo:
            print(f"{d.name:28s} {d.path:34s} {d.what}")
        return 0
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        roots = []
        for k in range(max(1, args.jobs)):
            r = Path(tmp) / f"copy{k}"
            r.mkdir()
            _copy_repo(r)
            roots.append(r)
        # the same tests on the unmodified copy first: a test that already fails would report
        # every defect that reaches it "caught" (a spy left on a renamed call did, once)
        if not args.no_clean_check:
            code, text, dt = _run_tests(roots[0], args.tests)
            if code != 0:
                print(f"seeded_defects: the unmodified tree fails its tests ({code}, "
                      f"{_first_failure(text) or 'no test named'}) after {dt:.0f} s: fix that "
                      f"first; no defect was run", file=sys.stderr)
                return 2
            print(f"clean tree: the tests pass ({dt:.0f} s)", flush=True)
        # one scratch copy per worker; each defect is applied and reverted on its worker's copy
        free = list(roots)
        import threading
        lock = threading.Lock()

        def job(defect):
            with lock:
                root = free.pop()
            try:
                res = run_one(defect, root, args.tests)
            finally:
                with lock:
                    free.append(root)
            mark = {True: "caught", False: "MISSED", None: "NOT APPLIED"}[res["caught"]]
            print(f"{mark:11s} {defect.name:28s} {res['seconds']:6.1f} s  {res['test']}",
                  flush=True)
            return res

        with ThreadPoolExecutor(max_workers=len(roots)) as ex:
            results = list(ex.map(job, todo))
    wall = time.perf_counter() - t0
    caught = sum(r["caught"] is True for r in results)
    print(f"{caught}/{len(results)} defects caught in {wall:.0f} s")
    if not args.no_report:
        lines = ["# Seeded defects (tests/seeded_defects.py)", "",
                 f"{caught} of {len(results)} defects caught; {wall:.0f} s with {args.jobs} "
                 "suites in parallel. Each row: one small edit of the package, the first "
                 "test that failed on it (pytest -x; the tests not marked slow first, the "
                 "slow ones only if those passed), and the seconds until then.", "",
                 "| defect | what | file | first failing test | s |", "|---|---|---|---|---|"]
        for r in results:
            d = r["defect"]
            test = r["test"] if r["caught"] else f"**{r['test']}**"
            lines.append(f"| {d.name} | {d.what} | `{d.path}` | {test} | {r['seconds']:.1f} |")
        report = (Path(args.report) if args.report else
                  REPORT.with_name("seeded_defects_partial.md") if args.only else REPORT)
        if args.no_clean_check:
            lines[2] += " The tests were not run on the unmodified tree first (--no-clean-check)."
        if args.only:
            lines[2] = (f"Partial run (--only {args.only}"
                        + (f" --tests {' '.join(args.tests)}" if args.tests else "")
                        + "): " + lines[2])
        report.write_text("\n".join(lines) + "\n")
        print(f"report: {report}")
    return 0 if caught == len(results) else 1


if __name__ == "__main__":
    sys.exit(main())
