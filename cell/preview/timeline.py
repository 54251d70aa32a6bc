"""The quaternions of rotation matrices that the Rerun recording (:mod:`cell.preview.rerun`) logs, numpy only."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray


def quaternions_xyzw(R: npt.ArrayLike) -> FloatArray:
    """(n, 4) unit quaternions (x, y, z, w) of rotation matrices (n, 3, 3) (Shepperd's method)."""
    m = np.asarray(R, dtype=float).reshape(-1, 3, 3)
    tr = np.trace(m, axis1=1, axis2=2)
    d = np.stack([m[:, 0, 0], m[:, 1, 1], m[:, 2, 2], tr], axis=1)
    k = np.argmax(d, axis=1)
    q = np.empty((len(m), 4))
    for i in range(len(m)):
        a = m[i]
        if k[i] == 3:
            s = 2.0 * np.sqrt(1.0 + tr[i])
            q[i] = [(a[2, 1] - a[1, 2]) / s, (a[0, 2] - a[2, 0]) / s, (a[1, 0] - a[0, 1]) / s, 0.25 * s]
        else:
            j, n = (k[i] + 1) % 3, (k[i] + 2) % 3
            s = 2.0 * np.sqrt(max(1.0 + a[k[i], k[i]] - a[j, j] - a[n, n], 1e-12))
            v = np.empty(4)
            v[k[i]] = 0.25 * s
            v[j] = (a[j, k[i]] + a[k[i], j]) / s
            v[n] = (a[n, k[i]] + a[k[i], n]) / s
            v[3] = (a[n, j] - a[j, n]) / s
            q[i] = v
    q *= np.where(q[:, 3:4] < 0.0, -1.0, 1.0)
    return np.asarray(q / np.linalg.norm(q, axis=1, keepdims=True))
