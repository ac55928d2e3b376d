"""The cone sums a collocation returns: the solid-angle weighted VIIRS sums in nested discs about every
perturbed LOS, made from the difference arrays the kernel fills (:mod:`monitor.collocation.collocate`).

Smoothed over the perturbations. A cone counts a pixel whole when its centre lies inside (Wang et al. 2016),
so as the LOS is perturbed the cone's mean jumps by a pixel's share each time its edge crosses a pixel
centre. On the I grid a pixel is one perturbation step wide; on the M grid it is two, and a cone holds a
quarter as many: the jumps are larger, and where the scene leaves the cost shallow the minimum moves with
them (studies/second-band.md). Averaging each perturbation's sums with its neighbours', weights 1/4, 1/2,
1/4 along each axis, is the cone test made on each pixel spread over its centre and one step either side
(the perturbations are shifts of the cone, a pixel's shift the opposite one): the edge then moves through a
pixel gradually instead of at once, at the cost of a blur of one step in a cone of some 19 steps' radius.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numba
import numpy as np

from monitor.compiled.threads import KERNEL_LOCK


@numba.njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def _finish(
    acc: np.ndarray, whole: np.ndarray, solid: np.ndarray, sums: np.ndarray, weights: np.ndarray
) -> None:
    """Each FOV's disc sums from its difference arrays acc (F, discs, m, m + 1) complex and what every
    perturbation holds, *whole* (F, discs): the running sums along j from that give weight x radiance
    (real, into *sums*) and weight (imaginary, into *weights*); a weight
    below 1e-9 of the disc's *solid* angle (discs,) is what rounding leaves of the runs that passed an empty
    disc (~1e-16 of the row's weight; one pixel weighs ~1e-3 of a cone's solid angle) and is set to 0."""
    nk = acc.shape[1]
    m = sums.shape[2]
    for f in numba.prange(acc.shape[0]):
        for k in range(nk):
            for i in range(m):
                s = whole[f, k].real
                w = whole[f, k].imag
                for j in range(m):
                    s += acc[f, k, i, j].real
                    w += acc[f, k, i, j].imag
                    occupied = w > 1e-9 * solid[k]
                    sums[f, k, i, j] = s if occupied else 0.0
                    weights[f, k, i, j] = w if occupied else 0.0


@dataclass(frozen=True)
class ConeSums:
    """Solid-angle weighted VIIRS sums in nested discs about every perturbed LOS of a batch of F FOVs:
    *sums* (F, K, m, m) weight x radiance and *weights* (F, K, m, m) weight (sr) of disc k (radius
    ``radii_rad[k]``, increasing), *solid_sr* (K,) each disc's solid angle; *rendered*, when the pixels
    were rendered as each FOV row sees them standing at a height, the same discs' sums of that radiance."""

    radii_rad: tuple[float, ...]
    sums: np.ndarray
    weights: np.ndarray
    solid_sr: np.ndarray
    rendered: ConeSums | None = None

    def mean(self, k: int = 0) -> np.ndarray:
        """The weighted mean radiance in disc *k*.

        Parameters
        ----------
        k : int
            The disc, 0 the innermost.

        Returns
        -------
        numpy.ndarray
            Band radiance, mW/(m2 sr cm-1), shape (F, m, m); NaN where the disc holds no pixel.
        """
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(self.weights[:, k] > 0, self.sums[:, k] / self.weights[:, k], np.nan)

    def coverage(self, k: int = -1) -> np.ndarray:
        """The share of disc *k*'s solid angle that usable pixels cover.

        Parameters
        ----------
        k : int, optional
            The disc; the outermost by default.

        Returns
        -------
        numpy.ndarray
            Shares 0..1, shape (F, m, m).
        """
        return self.weights[:, k] / self.solid_sr[k]

    def annulus_means(self) -> np.ndarray:
        """The weighted mean radiance in each annulus between consecutive discs (the first: the innermost
        disc).

        Returns
        -------
        numpy.ndarray
            Band radiance, mW/(m2 sr cm-1), shape (F, K, m, m); NaN where an annulus holds no pixel.
        """
        s = np.diff(self.sums, axis=1, prepend=0.0)
        w = np.diff(self.weights, axis=1, prepend=0.0)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(w > 0, s / w, np.nan).astype(np.float32)


def _tent(a: np.ndarray) -> np.ndarray:
    """*a* (..., m, m) averaged along its last two axes with weights 1/4, 1/2, 1/4, the edges repeated."""
    for axis in (-2, -1):
        pad = [(0, 0)] * a.ndim
        pad[axis] = (1, 1)
        p = np.pad(a, pad, mode="edge")
        m = a.shape[axis]
        a = 0.25 * (
            np.take(p, np.arange(m), axis=axis)
            + 2.0 * np.take(p, np.arange(1, m + 1), axis=axis)
            + np.take(p, np.arange(2, m + 2), axis=axis)
        )
    return a


def smoothed(cones: ConeSums) -> ConeSums:
    """The cone sums averaged over each perturbation and its neighbours (module docstring).

    Parameters
    ----------
    cones : ConeSums
        Sums over a (2n+1) x (2n+1) perturbation grid.

    Returns
    -------
    ConeSums
        The sums and weights of every disc, and of the rendered views, each perturbation's with weight 1/2
        along each axis and its two neighbours' with 1/4 (at the grid's edge, itself in the missing one's
        place); the discs' solid angles unchanged.
    """
    rendered = None if cones.rendered is None else smoothed(cones.rendered)
    return replace(cones, sums=_tent(cones.sums), weights=_tent(cones.weights), rendered=rendered)


def cone_sums_of(
    acc: np.ndarray, whole: np.ndarray, solid: np.ndarray, radii_rad: tuple[float, ...]
) -> ConeSums:
    """The cone sums of the kernel's difference arrays (:func:`_finish`).

    Parameters
    ----------
    acc : numpy.ndarray
        The runs' ends, complex (weight x radiance + i weight), shape (F, discs largest first, m, m + 1).
    whole : numpy.ndarray
        What every perturbation of a disc holds, complex, shape (F, discs).
    solid : numpy.ndarray
        The discs' solid angles, sr, in that order.
    radii_rad : tuple of float
        The discs' half-angles, rad, increasing.

    Returns
    -------
    ConeSums
        The sums, the smallest disc first.
    """
    nf, nk, m = acc.shape[0], acc.shape[1], acc.shape[2]
    sums, weights = np.empty((nf, nk, m, m)), np.empty((nf, nk, m, m))
    with KERNEL_LOCK:
        _finish(acc, whole, solid, sums, weights)
    return ConeSums(tuple(radii_rad), sums[:, ::-1], weights[:, ::-1], solid[::-1])
