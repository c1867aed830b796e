"""Butterworth filters as second-order sections (order 1 and 2: one; an even order N: N / 2), without scipy.signal.

``sos_row(order, cutoff_hz, rate, btype)`` gives the row ``[b0 b1 b2 1 a1 a2]``
that ``scipy.signal.butter(order, cutoff_hz, btype, fs=rate, output="sos")[0]``
gives, bit for bit: the same steps in the same floating-point operations.
Importing scipy.signal costs a process about 50 MB (it loads scipy.stats,
optimize, interpolate, sparse, spatial and ndimage); ``studyapp simulate``
needs only these few sections (issue 30, item 4).

The design (scipy's ``iirfilter``): the analog prototype's poles
p_m = -exp(j pi m / (2N)), m = -N+1, -N+3, ..., N-1, with gain 1 and no
zeros; the cut-off prewarped on the normalised scale (fs = 2),
w = 4 tan(pi W / 2) with W = f_c / (rate / 2); low-pass p -> w p, gain w^N;
high-pass p -> w / p, N zeros at 0, gain Re(1 / prod(-p)); then the bilinear
transform s -> z = (4 + s) / (4 - s), zeros at infinity to z = -1, the gain
times Re(prod(4 - zeros) / prod(4 - poles)). A conjugate pole pair enters the
section as its mean (p + conj(p'))/2 and its conjugate (scipy's ``_cplxreal``);
an order-1 filter pairs its pole and zero with a pole and a zero at 0.

``sos_rows(order, ...)`` for an even order (the bowing verdict's 4th-order
high-pass) pairs the poles as scipy's ``zpk2sos`` does: the pair nearest the
unit circle in the last section, the gain in the first; its rows equal
scipy's bit for bit on the tested grid (orders 4-8, 6-96 kHz, low and high).
"""

import numpy as np

BTYPES = ("low", "high")


def _poly(roots):
    """Polynomial coefficients with ``roots`` (numpy's ``poly``: convolutions; real for conjugate roots)."""
    roots = np.asarray(roots)
    a = np.ones((1,), dtype=roots.dtype)
    one = np.ones_like(roots[0])
    for root in roots:
        a = np.convolve(a, np.stack((one, -root)), mode="full")
    if np.iscomplexobj(a):
        imag = np.imag(np.asarray(roots, dtype=np.complex128))
        if np.all(np.sort(imag) == np.sort(-imag)):
            a = np.real(a).copy()
    return a


def _zpk(order, cutoff_hz, rate, btype):
    """The digital filter's zeros, poles and gain, as scipy's ``butter(..., output="zpk")``."""
    wn = np.asarray(cutoff_hz, dtype=np.float64) / (float(rate) / 2)
    if not 0 < wn < 1:
        raise ValueError(f"cut-off {cutoff_hz!r} Hz: allowed is above 0 and below rate / 2 = {float(rate) / 2:g} Hz")
    fs = 2.0
    warped = float(2 * fs * np.tan(np.pi * wn / fs))
    z = np.asarray([], dtype=np.float64)
    p = -np.exp(1j * np.pi * np.arange(-order + 1, order, 2, dtype=np.float64) / (2 * order))
    k = 1.0
    if btype == "low":
        z, p, k = warped * z, warped * p, k * warped ** order
    else:
        z, p, k = (np.concatenate((warped / z, np.zeros(order))), warped / p,
                   k * np.real(np.prod(-z) / np.prod(-p)))
    degree = len(p) - len(z)
    fs2 = 2.0 * fs
    z_z = np.concatenate(((fs2 + z) / (fs2 - z), -np.ones(degree)))
    p_z = (fs2 + p) / (fs2 - p)
    k_z = k * np.real(np.prod(fs2 - z) / np.prod(fs2 - p))
    return z_z, p_z, k_z


def sos_row(order, cutoff_hz, rate, btype="low"):
    """One section ``[b0, b1, b2, 1, a1, a2]``: a Butterworth ``btype`` ("low"/"high") filter of order 1 or 2."""
    if order not in (1, 2):
        raise ValueError(f"order {order!r}: allowed are 1 and 2")
    if btype not in BTYPES:
        raise ValueError(f"btype {btype!r}: allowed are {', '.join(BTYPES)}")
    z, p, k = _zpk(order, cutoff_hz, rate, btype)
    if order == 2:  # one conjugate pair of poles (as their mean), two equal real zeros
        zp, zn = (p[:1], p[1:]) if p[0].imag > 0 else (p[1:], p[:1])
        pole = ((zp + zn.conj()) / 2)[0]
        poles, zeros = [pole, pole.conj()], np.sort(z.real)
    else:  # the real pole nearest the unit circle first, then the zero nearest it
        reals = np.sort(np.array([p[0].real, 0.0]))
        p1 = reals[int(np.argmin(np.abs(1 - np.abs(reals))))]
        poles = [p1, reals[1] if p1 == reals[0] else reals[0]]
        reals = np.sort(np.array([z[0].real, 0.0]))
        z1 = reals[int(np.argsort(np.abs(reals - p1))[0])]
        zeros = [z1, reals[1] if z1 == reals[0] else reals[0]]
    row = np.zeros(6)
    row[:3] = np.multiply(np.ones(1), _poly(np.asarray(zeros, dtype=np.float64)))
    row[3:] = _poly(np.asarray(poles))
    row[:3] *= np.asarray(k).real
    return row


def sos_rows(order, cutoff_hz, rate, btype="low"):
    """``order`` / 2 sections (an even ``order``; 1 and 2 as ``sos_row``), the poles nearest the unit circle last."""
    if order in (1, 2):
        return sos_row(order, cutoff_hz, rate, btype)[None, :]
    if order % 2 or not 2 < order <= 16:
        raise ValueError(f"order {order!r}: allowed are 1 and the even orders 2..16")
    if btype not in BTYPES:
        raise ValueError(f"btype {btype!r}: allowed are {', '.join(BTYPES)}")
    z, p, k = _zpk(order, cutoff_hz, rate, btype)
    upper = p[p.imag > 0]
    lower = p[p.imag < 0]
    pairs = [((q + lower[int(np.argmin(np.abs(lower - q.conj())))].conj()) / 2) for q in upper]
    pairs.sort(key=lambda q: -abs(1 - abs(q)))  # farthest from the unit circle first
    zero = np.sort(z.real)[0]  # every zero of a Butterworth section is at z = 1 (high) or z = -1 (low)
    rows = np.zeros((order // 2, 6))
    for j, pole in enumerate(pairs):
        rows[j, :3] = _poly(np.asarray([zero, zero], dtype=np.float64))
        rows[j, 3:] = _poly(np.asarray([pole, pole.conj()]))
    rows[0, :3] *= np.asarray(k).real
    return rows
