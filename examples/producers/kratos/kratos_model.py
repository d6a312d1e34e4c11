"""Kratos' side of ``export.py``: the two membranes, the mesh tying, the blocks of its LHS."""
from __future__ import annotations

import json
import os
from importlib.metadata import version as _dist_version
from pathlib import Path

import numpy as np
import scipy.io
import scipy.sparse as sp

import KratosMultiphysics as KM
import KratosMultiphysics.ContactStructuralMechanicsApplication as CSMA
import KratosMultiphysics.ConvectionDiffusionApplication  # noqa: F401  (registers LaplacianElement2D3N)
from KratosMultiphysics.ContactStructuralMechanicsApplication import mesh_tying_process

KM.Logger.GetDefaultOutput().SetSeverity(KM.Logger.Severity.WARNING)
DUAL_P1 = np.array([[2.0, -1.0], [-1.0, 2.0]])
"""The element-wise biorthogonal dual of P1 in the two P1 shapes: ψ_a = 2φ_a − φ_b."""


def version() -> str:
    """Kratos' distribution version (the manifest's ``name``)."""
    return _dist_version("KratosMultiphysics")


def _model(n1: int, n2: int, scaled: bool, fix_ends: bool):
    """The model part: Ω1 (n1 × n1 squares, two triangles each), Ω2 (n2 × n2), Γ line
    conditions on both sides, the mesh tying process initialised (slave = Ω1's side);
    ``fix_ends``: the multipliers of Γ's two end nodes fixed (SCALAR_LAGRANGE_MULTIPLIER.Fix)."""
    model = KM.Model()
    mp = model.CreateModelPart("Structure")
    mp.ProcessInfo[KM.DOMAIN_SIZE] = 2
    mp.ProcessInfo[KM.STEP] = 1  # the search runs on step 1 of its interval
    mp.ProcessInfo[KM.TIME] = 1.0
    for var in (KM.TEMPERATURE, KM.HEAT_FLUX, KM.CONDUCTIVITY, KM.REACTION_FLUX, KM.SCALAR_LAGRANGE_MULTIPLIER,
                CSMA.WEIGHTED_SCALAR_RESIDUAL, KM.NORMAL, KM.NODAL_H):
        mp.AddNodalSolutionStepVariable(var)
    settings = KM.ConvectionDiffusionSettings()
    settings.SetUnknownVariable(KM.TEMPERATURE)
    settings.SetDiffusionVariable(KM.CONDUCTIVITY)
    settings.SetVolumeSourceVariable(KM.HEAT_FLUX)
    settings.SetReactionVariable(KM.REACTION_FLUX)
    mp.ProcessInfo.SetValue(KM.CONVECTION_DIFFUSION_SETTINGS, settings)
    prop = mp.GetProperties()[1]
    prop.SetValue(KM.CONDUCTIVITY, 1.0)
    prop.SetValue(KM.YOUNG_MODULUS, 1.0)  # the automatic scale factor is YOUNG_MODULUS / NODAL_H
    counter = {"node": 0, "elem": 0, "cond": 0}
    grids = [_grid(mp, prop, counter, n1, 0.0), _grid(mp, prop, counter, n2, 1.0)]
    for node in mp.Nodes:
        node.SetSolutionStepValue(KM.CONDUCTIVITY, 1.0)
    gamma_rows = (-1, 0)  # Γ is Ω1's top row and Ω2's bottom row
    for k, (ids, row) in enumerate(zip(grids, gamma_rows)):
        sub = mp.CreateSubModelPart(f"Gamma{k + 1}")
        line = [int(i) for i in ids[row, :]]
        sub.AddNodes(line)
        if row == -1:
            line = line[::-1]  # the line's normal points out of its body
        for a, b in zip(line[:-1], line[1:]):
            counter["cond"] += 1
            sub.CreateNewCondition("LineCondition2D2N", counter["cond"], [a, b], prop)
        boundary = set(ids[0, :]) | set(ids[-1, :]) | set(ids[:, 0]) | set(ids[:, -1])
        for node_id in boundary - set(ids[row, 1:-1]):  # u = 0 on ∂Ω_i \ Γ (Γ's end nodes too)
            mp.GetNode(int(node_id)).Fix(KM.TEMPERATURE)
    KM.VariableUtils().AddDof(KM.TEMPERATURE, KM.REACTION_FLUX, mp)
    KM.VariableUtils().AddDof(KM.SCALAR_LAGRANGE_MULTIPLIER, CSMA.WEIGHTED_SCALAR_RESIDUAL, mp)
    tying = {"model_part_name": "Structure", "mesh_tying_model_part": {"0": ["Gamma1", "Gamma2"]},
             "assume_master_slave": {"0": ["Gamma1"]}, "variable_name": "TEMPERATURE"}
    if not scaled:
        tying["scale_factor_parameters"] = {"manual_scale_factor": True, "scale_factor": 1.0}
    process = mesh_tying_process.Factory(KM.Parameters(json.dumps({"Parameters": tying})), model)
    process.ExecuteInitialize()
    process.ExecuteBeforeSolutionLoop()
    process.ExecuteInitializeSolutionStep()
    if fix_ends:
        for node_id in (grids[0][-1, 0], grids[0][-1, -1]):
            mp.GetNode(int(node_id)).Fix(KM.SCALAR_LAGRANGE_MULTIPLIER)
    return model, mp, grids


def _grid(mp, prop, counter, n: int, y0: float) -> np.ndarray:
    """Nodes (ids row by row, left to right) and triangles of (0,1)×(y0, y0+1), n squares a side."""
    ids = np.zeros((n + 1, n + 1), int)
    for j in range(n + 1):
        for i in range(n + 1):
            counter["node"] += 1
            mp.CreateNewNode(counter["node"], i / n, y0 + j / n, 0.0)
            ids[j, i] = counter["node"]
    for j in range(n):
        for i in range(n):
            a, b, c, d = (int(x) for x in (ids[j, i], ids[j, i + 1], ids[j + 1, i + 1], ids[j + 1, i]))
            for tri in ((a, b, c), (a, c, d)):
                counter["elem"] += 1
                mp.CreateNewElement("LaplacianElement2D3N", counter["elem"], list(tri), prop)
    return ids


def assembled_blocks(n1: int, n2: int, space: str):
    """Kratos' LHS after its Dirichlet treatment, split by dof type.

    ``dual`` and ``dual-unscaled`` use Kratos' block builder (its default: fixed dofs stay in
    the system, row and column zeroed, the diagonal kept); ``dual-ends-fixed`` its elimination
    builder (fixed dofs left out of the system), with the end multipliers fixed.

    Returns
    -------
    dict
        ``A``, ``B`` (scipy CSR: TEMPERATURE × TEMPERATURE and SCALAR_LAGRANGE_MULTIPLIER ×
        TEMPERATURE, in Kratos' equation order within each type); ``xy`` and ``ids``: the
        TEMPERATURE dofs' coordinates (n × 2) and node ids (Ω1's nodes are 1 .. (n1 + 1)²);
        ``lm_x``: the multipliers' x on Γ; ``fixed``: which TEMPERATURE dofs Kratos fixed;
        ``scale``: Kratos' SCALE_FACTOR (1 for the unscaled spaces: B then carries none).
    """
    from KratosMultiphysics import scipy_conversion_tools

    model, mp, _ = _model(n1, n2, scaled=(space == "dual"), fix_ends=(space == "dual-ends-fixed"))
    linear = KM.LinearSolverFactory().Create(KM.Parameters('{"solver_type": "skyline_lu_factorization"}'))
    scheme = KM.ResidualBasedIncrementalUpdateStaticScheme()
    if space == "dual-ends-fixed":
        builder = KM.ResidualBasedEliminationBuilderAndSolver(linear)
    else:
        builder = KM.ResidualBasedBlockBuilderAndSolver(linear)
    strategy = KM.ResidualBasedLinearStrategy(mp, scheme, builder, False, False, False, False)
    strategy.Initialize()
    strategy.InitializeSolutionStep()
    lhs, rhs, dx = strategy.GetSystemMatrix(), strategy.GetSystemVector(), strategy.GetSolutionVector()
    builder.Build(scheme, mp, lhs, rhs)
    builder.ApplyDirichletConditions(scheme, mp, lhs, dx, rhs)  # what BuildAndSolve does before solving
    full = scipy_conversion_tools.to_csr(lhs).tocsr()
    temp, lm = [], []
    size = full.shape[0]
    for dof in builder.GetDofSet():
        if dof.EquationId >= size:  # a dof the elimination builder left out (fixed)
            continue
        node = mp.GetNode(dof.Id())
        entry = (dof.EquationId, node.X, node.Y, dof.IsFixed(), node.Id)
        (temp if dof.GetVariable().Name() == "TEMPERATURE" else lm).append(entry)
    temp.sort()
    lm.sort()
    t_eq = [e[0] for e in temp]
    l_eq = [e[0] for e in lm]
    A = full[t_eq][:, t_eq].tocsr()
    B = full[l_eq][:, t_eq].tocsr()
    if abs(full[t_eq][:, l_eq] - B.T).max() != 0:
        raise RuntimeError("Kratos' LHS is not symmetric in the multiplier coupling")
    if full[l_eq][:, l_eq].count_nonzero():
        raise RuntimeError("Kratos assembled a multiplier block: G would not be the L2 mass alone")
    # a manual scale factor never reaches the conditions (Kratos 10.4.4: the process keeps it on
    # its Python object; SCALE_FACTOR stays 0 and B comes out unscaled whatever the value: measured)
    scale = mp.ProcessInfo.GetValue(KM.SCALE_FACTOR) if space == "dual" else 1.0
    return dict(A=A, B=B, xy=np.array([[e[1], e[2]] for e in temp]), ids=np.array([e[4] for e in temp]),
                lm_x=np.array([e[1] for e in lm]), fixed=np.array([e[3] for e in temp]), scale=scale)


def dual_mass(breakpoints: np.ndarray) -> sp.csr_matrix:
    """The L² mass of the dual P1 basis on ``breakpoints`` (rows left to right), 2-point Gauss."""
    x, w = np.polynomial.legendre.leggauss(2)  # exact for the products of two P1 functions
    t = (x + 1) / 2
    phi = np.vstack([1 - t, t])  # the P1 shapes at the points
    psi = DUAL_P1 @ phi
    local = (psi * (w / 2)) @ psi.T
    m = len(breakpoints)
    G = sp.lil_matrix((m, m))
    for e, h in enumerate(np.diff(breakpoints)):
        G[e:e + 2, e:e + 2] = G[e:e + 2, e:e + 2].toarray() + h * local
    return G.tocsr()


def write_level(out: Path, n: int, offset: int, space: str) -> dict:
    """One level's A, B, G (MatrixMarket, 17 digits) and its manifest entry."""
    blocks = assembled_blocks(n + offset, n, space)
    A, B, lm_x = blocks["A"], blocks["B"], blocks["lm_x"]
    rows = np.argsort(lm_x, kind="stable")  # rows[j] = row of B holding the j-th basis function left to right
    if space == "dual-ends-fixed":  # the slave mesh's nodes: the free multipliers and Γ's two ends
        breakpoints = np.concatenate([[0.0], lm_x[rows], [1.0]])
        G_sorted = dual_mass(breakpoints)[1:-1, 1:-1]
        mult = _dual_without_ends(breakpoints, rows)
    else:
        breakpoints = lm_x[rows]
        G_sorted = dual_mass(breakpoints)
        mult = {"basis": "dual", "degree": 1, "breakpoints": [float(b) for b in breakpoints], "ends": "keep"}
        if not np.array_equal(rows, np.arange(len(rows))):
            mult["rows"] = [int(r) for r in rows]
    inv = np.argsort(rows)
    G = G_sorted[inv][:, inv]  # into B's row order
    files = {}
    for key, mat in (("A", A), ("B", B), ("G", G)):
        name = f"{key}{n}.mtx"
        tmp = out / f".{name}.tmp"
        scipy.io.mmwrite(str(tmp), sp.coo_matrix(mat), precision=17)
        written = Path(str(tmp) + ".mtx") if not tmp.exists() else tmp
        os.replace(written, out / name)
        files[key] = name
    return dict(h=1.0 / n, multipliers=mult, **files)


def _dual_without_ends(breakpoints: np.ndarray, rows: np.ndarray) -> dict:
    """The general form of the dual P1 functions of the interior nodes, unmodified at Γ's
    ends (ψ_1 = 2φ_1 − φ_0 on the first interval): per interval the rows of its two nodes'
    functions (−1 at an end node) and the dual coefficients."""
    m = len(rows)
    node_row = np.concatenate([[-1], rows, [-1]])  # node j (left to right) → its row of B
    dofs = [[int(node_row[e]), int(node_row[e + 1])] for e in range(m + 1)]
    return {"breakpoints": [float(b) for b in breakpoints], "degree": 1, "dofs": dofs,
            "coefficients": DUAL_P1.tolist()}
