"""The parcel store on the device: appending injected parcels, the counting sort by cell that also drops the
parcels that left (compaction), copies between parcel buffers, and the reductions a fluid step reports.
Layout: hfgpu.kernels.layout. NumPy reference of the order: hfgpu.proppant.parcels.Parcels.sort_by_cell
(the same keys, a stable sort) followed by dropping the GONE parcels.
"""

from hfgpu.kernels.layout import (GONE, P_DX, P_DZ, P_X0, P_Z0, PARCEL_ROWS, STATE, STATE_ROWS, ST_GONE,
                                  ST_LIVE, X, Z)
from hfgpu.kernels.runtime import ti


@ti.func
def append(P: ti.template(), S: ti.template(), n: ti.i32, values: ti.template(), ints: ti.template()):
    """Columns n, n + 1, ... of P and S from the host's new parcels, values (PARCEL_ROWS, m), ints
    (STATE_ROWS, m)."""
    for j, p in ti.ndrange((0, PARCEL_ROWS), (0, values.shape[1])):
        P[j, n + p] = values[j, p]
    for j, p in ti.ndrange((0, STATE_ROWS), (0, ints.shape[1])):
        S[j, n + p] = ints[j, p]


@ti.func
def copy_parcels(P: ti.template(), S: ti.template(), P2: ti.template(), S2: ti.template(), n: ti.i32):
    """The first n parcels of P, S into P2, S2."""
    for j, p in ti.ndrange((0, PARCEL_ROWS), (0, n)):
        P2[j, p] = P[j, p]
    for j, p in ti.ndrange((0, STATE_ROWS), (0, n)):
        S2[j, p] = S[j, p]


@ti.func
def sort_key(P: ti.template(), S: ti.template(), p: ti.i32, nz: ti.i64, nx: ti.i64, PR: ti.template()) -> ti.i64:
    """Half-cell index of parcel p, row-major (depth, then x), clipped into [0, (2 nz + 2)(2 nx + 2)); GONE
    parcels get the key past the last, (2 nz + 2)(2 nx + 2) (Parcels.sort_by_cell)."""
    key = (2 * nz + 2) * (2 * nx + 2)
    if S[STATE, p] != GONE:
        kq = ti.cast(ti.floor(2.0 * (P[Z, p] - PR[P_Z0]) / PR[P_DZ]), ti.i64) + 1
        iq = ti.cast(ti.floor(2.0 * (P[X, p] - PR[P_X0]) / PR[P_DX]), ti.i64) + 1
        kq = ti.min(ti.max(kq, 0), 2 * nz + 1)
        iq = ti.min(ti.max(iq, 0), 2 * nx + 1)
        key = kq * (2 * nx + 2) + iq
    return key


@ti.func
def counting_sort(P: ti.template(), S: ti.template(), P2: ti.template(), S2: ti.template(), keys: ti.template(),
                  counts: ti.template(), n: ti.i32, nz: ti.i32, nx: ti.i32, stable: ti.template(),
                  PR: ti.template(), ST: ti.template()):
    """P2, S2 = the first n parcels of P, S ordered by sort_key (keys and counts: int64 scratch arrays), GONE
    parcels last and dropped: ST[ST_LIVE] is
    the number kept, ST[ST_GONE] the number dropped. A counting sort (Cormen et al., Introduction to
    Algorithms, 8.2): histogram of the keys, exclusive prefix sum, scatter. ``stable``: the scatter runs in
    parcel order (serial; the CPU, where it keeps every run reproducible), else each parcel takes its slot with
    an atomic (a GPU: parallel, order within a half cell arbitrary)."""
    buckets = ti.cast((2 * nz + 2) * (2 * nx + 2) + 1, ti.i32)
    for b in range(buckets):
        counts[b] = 0
    for p in range(n):
        key = sort_key(P, S, p, nz, nx, PR)
        keys[p] = key
        ti.atomic_add(counts[key], 1)
    ST[ST_LIVE] = 0.0
    ti.loop_config(serialize=True)
    for b in range(buckets):
        c = counts[b]
        counts[b] = ti.cast(ST[ST_LIVE], ti.i64)
        ST[ST_LIVE] += c
    ST[ST_LIVE] = ti.cast(counts[buckets - 1], ti.f64)
    ST[ST_GONE] = ti.cast(n - counts[buckets - 1], ti.f64)
    if ti.static(stable):
        ti.loop_config(serialize=True)
        for p in range(n):
            slot = counts[keys[p]]
            counts[keys[p]] = slot + 1
            for j in ti.static(range(PARCEL_ROWS)):
                P2[j, slot] = P[j, p]
            for j in ti.static(range(STATE_ROWS)):
                S2[j, slot] = S[j, p]
    else:
        for p in range(n):
            slot = ti.atomic_add(counts[keys[p]], 1)
            for j in ti.static(range(PARCEL_ROWS)):
                P2[j, slot] = P[j, p]
            for j in ti.static(range(STATE_ROWS)):
                S2[j, slot] = S[j, p]


__all__ = ["append", "copy_parcels", "counting_sort"]
