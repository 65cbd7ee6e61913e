"""What each plot shows, as plain arrays and dicts: no matplotlib here.

Every ``plot_*`` function in :mod:`mocycle.viz` draws one of these dicts, so another
front end (a web page, Blender) can draw the same figures its own way, and the
numbers can be tested without a plotting library.
"""

from __future__ import annotations

import numpy as np
from sklearn.decomposition import PCA

from ..cycle.metric_rows import metric_features
from ..errors import MocycleError
from ..features import pose_matrix
from ..rotations import mean_rotations


def _xy(X: np.ndarray, fit_rows: np.ndarray | None = None) -> tuple[np.ndarray, PCA | None]:
    """2-D PCA of the rows of ``X`` (fitted on ``fit_rows``); one column is padded with zeros."""
    if X.shape[1] >= 2:
        pca = PCA(n_components=2).fit(X if fit_rows is None else X[fit_rows])
        return pca.transform(X), pca
    return np.c_[X[:, 0], np.zeros(len(X))], None


def phase_plot_data(result) -> dict:
    """The ``mocycle phase --plot`` figure of a :class:`~mocycle.phase.PhaseResult`.

    Returns
    -------
    dict with ``barcode`` ``(B, 2)`` (birth, death); ``classes``: one dict per periodic motion
    (``birth``, ``death``, ``period_frames``, ``coords`` ``(T,)`` in cycles, ``excitation`` frame ranges);
    ``frames`` ``(T,)``; ``xy`` ``(T', 2)``: the PCA of the point cloud (``None`` when the result does not
    keep its features: ``find_phase(keep_features=True)``); ``phase`` ``(T',)``: the first class's
    coordinate per point (zeros when there is none); ``reason``: why these classes (or none).
    """
    classes = [{"birth": c.birth, "death": c.death, "period_frames": c.period_frames, "coords": c.coords,
                "excitation": list(c.excitation)} for c in result.classes]
    xy = phase = None
    if result.features is not None:
        xy, _ = _xy(result.features)
        phase = result.classes[0].coords[: len(xy)] if result.classes else np.zeros(len(xy))
    return {"barcode": np.asarray(result.barcode), "classes": classes, "frames": np.arange(result.n_frames),
            "xy": xy, "phase": phase, "reason": result.reason}


def loop_plot_data(motion, cycle, n_joints: int = 3) -> dict:
    """The ``mocycle loop --plot`` figure of a cycle extracted from ``motion``.

    Returns
    -------
    dict with ``input_xy`` ``(T, 2)`` and ``cycle_xy`` ``(N + 1, 2)`` (closed): the input's poses and the
    cycle in the 2-D PCA of the excited input frames (in the loop metrics' rotation-matrix space,
    :func:`~mocycle.cycle.metric_rows.metric_features`); ``frames`` ``(M,)``: the excited frames;
    ``input_phase`` ``(M,)``: where each falls in the cycle (cycles); ``coords`` ``(T,)``: the circular
    coordinate (``None`` for a blend); ``axis_phase`` ``(M,)``: the time axis mod 1; ``regions``;
    ``curves``: the ``n_joints`` most moving rotation-vector components about the mean pose, each with its
    ``name``, ``cycle_deg`` ``(2N,)`` over two repetitions and the input's ``input_deg`` ``(M,)`` at
    ``positions`` ``(M,)`` (cycle frames); ``n_frames``, ``n_periods``, ``period_frames``, ``method``,
    ``model``, ``axis_method``.
    """
    ref = mean_rotations(motion.rotations)
    inplace = cycle.motion("inplace")
    Y, C = metric_features(motion), metric_features(inplace)  # the metrics' wrap-free space
    frames = cycle.axis.frames()
    if Y.shape[1] >= 2:
        pca = PCA(n_components=2).fit(Y[frames])
        input_xy, cycle_xy = pca.transform(Y), pca.transform(np.vstack([C, C[:1]]))
    else:
        input_xy = np.c_[Y[:, 0], np.zeros(len(Y))]
        cycle_xy = np.c_[np.r_[C[:, 0], C[:1, 0]], np.zeros(len(C) + 1)]
    # The curves are what an animator reads: rotation-vector components about the mean pose (a joint turning
    # a full circle shows its turn as a 360° jump there; the PCA above has none).
    V, decoder = pose_matrix(motion, rep="quatlog", root_features="drop", reference=ref)
    V, Vc = 2.0 * V, 2.0 * pose_matrix(inplace, rep="quatlog", root_features="drop", reference=ref)[0]
    spread = np.ptp(V[frames], axis=0)
    cols = np.argsort(spread)[::-1][:n_joints]
    curves = [{"name": decoder.columns[col], "cycle_deg": np.degrees(np.tile(Vc[:, col], 2)),
               "input_deg": np.degrees(V[frames, col])} for col in cols]
    return {
        "input_xy": input_xy, "cycle_xy": cycle_xy, "frames": frames,
        "input_phase": np.mod(cycle.positions / cycle.n_frames, 1),
        "coords": None if cycle.periodic is None else cycle.periodic.coords,
        "axis_phase": np.mod(cycle.axis.x[frames], 1.0), "regions": list(cycle.axis.regions),
        "positions": cycle.positions, "curves": curves, "n_frames": cycle.n_frames, "n_periods": cycle.n_periods,
        "period_frames": cycle.period_frames, "method": cycle.method, "model": cycle.model,
        "axis_method": cycle.axis.method,
    }


def swings_plot_data(seg) -> dict:
    """The ``mocycle swings --plot`` figure of a :class:`~mocycle.swings.Segmentation`.

    Returns
    -------
    dict with ``rows``: one per segmented joint, top to bottom, each with ``name``, ``swings`` (``start_s``,
    ``duration_s``, ``turn_deg``: the angle turned through, ``index``: 0-based in time order, what
    ``edit --swing`` takes) and ``holds`` (``start_s``, ``end_s``);
    ``max_turn_deg``; ``duration_s`` (the take's last frame time); ``n_swings``, ``threshold``.
    """
    dt = seg.frame_time
    rows = []
    for j in seg.joints:
        swings = [{"start_s": s.start * dt, "duration_s": max(s.end - s.start, 1) * dt,
                   "turn_deg": float(abs(np.degrees(s.end_angle - s.start_angle))), "index": k}
                  for k, s in enumerate(seg.swings_of(j))]
        holds = [{"start_s": h.start * dt, "end_s": h.end * dt} for h in seg.holds_of(j)]
        rows.append({"name": seg.skeleton.names[j], "swings": swings, "holds": holds})
    turns = [s["turn_deg"] for r in rows for s in r["swings"]]
    return {"rows": rows, "max_turn_deg": max(turns) if turns else 1.0,
            "duration_s": max((seg.n_frames - 1) * dt, dt), "n_swings": seg.n_swings, "threshold": seg.threshold}


def projection_plot_data(points, key_idx, optimized=None, labels: tuple[str, str] = ("projection", "optimised"),
                         ) -> dict:
    """The ``mocycle project --plot`` figure: checked 2-D poses, keyframes, and an optional second panel.

    ``points``: ``(T, 2)``; ``key_idx``: keyframe indices; ``optimized``: ``(T, 2)`` or ``None``.  Returns a
    dict with ``panels`` (``points``, ``label``), ``key_idx`` and ``frames`` ``(T,)`` (the colour: time).
    """
    P = np.asarray(points, dtype=np.float64)
    idx = np.asarray(key_idx, dtype=np.int64)
    if P.ndim != 2 or P.shape[1] != 2 or len(P) < 1:
        raise MocycleError(f"points must have shape (T, 2); got {P.shape}")
    if idx.size and (idx.min() < 0 or idx.max() >= len(P)):
        raise MocycleError(f"keyframe indices must lie in 0..{len(P) - 1}")
    panels = [{"points": P, "label": labels[0]}]
    if optimized is not None:
        O = np.asarray(optimized, dtype=np.float64)
        if O.shape != P.shape:
            raise MocycleError(f"optimised points must have shape {P.shape}; got {O.shape}")
        panels.append({"points": O, "label": labels[1]})
    return {"panels": panels, "key_idx": idx, "frames": np.arange(len(P))}


def curves_plot_data(series, n_joints: int = 3) -> dict:
    """The ``blend``/``transition``/``stretch --plot`` figure: the ``n_joints`` most moving joint rotations of
    several motions.

    ``series``: ``(label, motion, x)`` with ``x`` ``(T,)`` where each frame goes on the horizontal axis
    (``None``: seconds). Returns ``names`` (the chosen rotation columns, e.g. ``"LeftLeg:qx"``) and
    ``series``: one dict per motion with ``label``, ``x`` ``(T,)`` and ``degrees`` ``(T, n_joints)``: the
    rotation from the first motion's mean pose (quaternion log, degrees).
    """
    first = series[0][1]
    ref = mean_rotations(first.rotations)
    names = pose_matrix(first[:1], rep="quatlog", root_features="drop", reference=ref)[1].columns
    # rotation vectors about the first motion's mean pose (2 x quaternion log, rad): angles a plot can label
    feats = [2.0 * pose_matrix(m, rep="quatlog", root_features="drop", reference=ref)[0] for _, m, _ in series]
    cols = np.argsort(np.ptp(feats[0], axis=0))[::-1][:n_joints]
    out = []
    for (label, motion, x), F in zip(series, feats, strict=True):
        xs = np.arange(motion.n_frames) * motion.frame_time if x is None else np.asarray(x, dtype=float)
        out.append({"label": label, "x": xs, "degrees": np.degrees(F[:, cols])})
    return {"names": [names[c] for c in cols], "series": out}
