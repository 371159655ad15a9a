#!/usr/bin/env python3
"""Why no deformation that agrees with the linear method to second order keeps a bent tube's rings.

The study behind docs/nonlinear.md, independent of Remora's code: a cylinder
(radius 1, height 4, 64 vertices around, 80 rings) with its bottom ring fixed and its top ring the
handle, k = 2 (cotan Laplacian, barycentric areas), details encoded against the k-harmonic fill B0
in a local frame per vertex and decoded in the deformed base's frames. It prints, for a 90° twist
and a 90° bend of the handle about its centroid, the worst ring's |mean radius - 1| of the decoded
surface, and for small angles the largest distance to the linear result, for:

  linear   the paper's method: the handle's map extended by the basis functions;
  blended  the handles' screw motions blended by their weights (Remora's blended-motions);
  fitted   per vertex, the screw whose rotation is fitted to the linear method's first-order field
           (the linear method applied to the map's logarithm) over the vertex's 1-ring, applied
           exactly (exp of the twist);
  lever    blended, plus the linear method's first-order field minus blended's.

fitted and lever agree with linear to second order (the distance quarters when the angle halves);
blended does not (it halves). Usage: python3 scripts/lever_study.py (numpy, scipy).
"""
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla
from scipy.spatial.transform import Rotation

AROUND, RINGS, HEIGHT = 64, 80, 4.0


def cylinder():
    """Staggered rings (each odd ring turned by half a step), two triangles per quad."""
    vertices = []
    for j, z in enumerate(np.linspace(0.0, HEIGHT, RINGS)):
        shift = 0.5 * np.pi / AROUND if j % 2 else 0.0
        for i in range(AROUND):
            t = 2 * np.pi * i / AROUND + shift
            vertices.append([np.cos(t), np.sin(t), z])
    faces = []
    for j in range(RINGS - 1):
        for i in range(AROUND):
            a, b = j * AROUND + i, j * AROUND + (i + 1) % AROUND
            c, d = a + AROUND, b + AROUND
            faces += [[a, b, c], [b, d, c]] if j % 2 == 0 else [[a, b, d], [a, d, c]]
    return np.array(vertices), np.array(faces)


def cotan_weights(v, f):
    """The cotan weights w_ij (symmetric, sparse) and the barycentric vertex areas."""
    rows, cols, weights = [], [], []
    for k in range(3):
        i, j, o = f[:, k], f[:, (k + 1) % 3], f[:, (k + 2) % 3]
        e1, e2 = v[i] - v[o], v[j] - v[o]
        cot = np.einsum('ij,ij->i', e1, e2) / np.linalg.norm(np.cross(e1, e2), axis=1)
        rows += [i, j]
        cols += [j, i]
        weights += [0.5 * cot, 0.5 * cot]
    n = len(v)
    w = sp.csr_matrix((np.concatenate(weights), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(n, n))
    face_area = 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)
    area = np.zeros(n)
    for k in range(3):
        np.add.at(area, f[:, k], face_area / 3)
    return w, area


def hat(x):
    return np.array([[0, -x[2], x[1]], [x[2], 0, -x[0]], [-x[1], x[0], 0]])


def se3_log(r, t):
    """(ω, v) with exp of the twist equal to p ↦ r p + t."""
    omega = Rotation.from_matrix(r).as_rotvec()
    theta = np.linalg.norm(omega)
    if theta < 1e-12:
        return omega, t
    k = hat(omega)
    v_inv = np.eye(3) - 0.5 * k + (1 - theta * np.sin(theta) / (2 * (1 - np.cos(theta)))) / theta**2 * k @ k
    return omega, v_inv @ t


def se3_exp(omega, v):
    """(r, t) of the twist (ω, v)."""
    theta = np.linalg.norm(omega)
    k = hat(omega)
    if theta < 1e-12:
        return np.eye(3) + k, v
    r = np.eye(3) + np.sin(theta) / theta * k + (1 - np.cos(theta)) / theta**2 * k @ k
    v_mat = np.eye(3) + (1 - np.cos(theta)) / theta**2 * k + (theta - np.sin(theta)) / theta**3 * k @ k
    return r, v_mat @ v


class Study:
    def __init__(self):
        self.v, self.f = cylinder()
        n = len(self.v)
        self.w, area = cotan_weights(self.v, self.f)
        laplacian = self.w - sp.diags(np.asarray(self.w.sum(1)).ravel())
        k2 = (laplacian @ sp.diags(1 / area) @ laplacian).tocsr()
        self.fixed = np.arange(AROUND)
        self.handle = np.arange((RINGS - 1) * AROUND, RINGS * AROUND)
        constrained = np.concatenate([self.fixed, self.handle])
        free = np.setdiff1d(np.arange(n), constrained)
        solve = sla.factorized(k2[free][:, free].tocsc())
        coupling = k2[free][:, constrained]

        def extend(values):  # the k-harmonic extension of values on the constrained vertices
            out = np.zeros((n, values.shape[1]))
            out[constrained] = values
            rhs = -coupling @ values
            out[free] = np.column_stack([solve(rhs[:, c]) for c in range(values.shape[1])])
            return out

        zeros_f, zeros_h = np.zeros((len(self.fixed), 3)), np.zeros((len(self.handle), 3))
        self.fixed_part = extend(np.vstack([self.v[self.fixed], zeros_h]))
        self.handle_part = extend(np.vstack([zeros_f, self.v[self.handle]]))
        self.weight = extend(np.vstack([zeros_f[:, :1], np.ones((len(self.handle), 1))]))[:, 0]
        self.b0 = self.fixed_part + self.handle_part
        self.details = np.einsum('nij,ni->nj', self.frames(self.b0), self.v - self.b0)
        self.centre = self.v[self.handle].mean(0)
        coo = self.w.tocoo()
        self.ring = (coo.row, coo.col, np.maximum(coo.data, 1e-8))

    def frames(self, x):
        """Per vertex: its normal and two tangents (the first neighbour's edge, projected)."""
        normals = np.zeros_like(x)
        cross = np.cross(x[self.f[:, 1]] - x[self.f[:, 0]], x[self.f[:, 2]] - x[self.f[:, 0]])
        for k in range(3):
            np.add.at(normals, self.f[:, k], cross)
        normals /= np.linalg.norm(normals, axis=1)[:, None]
        neighbour = np.zeros(len(x), int)
        for k in range(3):
            neighbour[self.f[:, k]] = self.f[:, (k + 1) % 3]
        tangent = x[neighbour] - x
        tangent -= np.einsum('ij,ij->i', tangent, normals)[:, None] * normals
        tangent /= np.linalg.norm(tangent, axis=1)[:, None]
        return np.stack([normals, tangent, np.cross(normals, tangent)], axis=2)

    def decode(self, base):
        return base + np.einsum('nij,nj->ni', self.frames(base), self.details)

    def motion(self, kind, angle):
        axis = np.array([0.0, 0.0, 1.0]) if kind == 'twist' else np.array([1.0, 0.0, 0.0])
        r = Rotation.from_rotvec(axis * angle).as_matrix()
        return r, self.centre - r @ self.centre

    def constrain(self, x, r, t):
        x[self.fixed] = self.b0[self.fixed]
        x[self.handle] = self.b0[self.handle] @ r.T + t
        return x

    def linear(self, r, t):
        return self.fixed_part + self.handle_part @ r.T + np.outer(self.weight, t)

    def first_order(self, omega, v):
        """The linear method applied to the map's logarithm p ↦ ω × p + v."""
        return self.handle_part @ hat(omega).T + np.outer(self.weight, v)

    def blended(self, r, t):
        omega, v = se3_log(r, t)
        x = np.empty_like(self.b0)
        for i, (p, w) in enumerate(zip(self.b0, self.weight)):
            ri, ti = se3_exp(w * omega, w * v)
            x[i] = ri @ p + ti
        return self.constrain(x, r, t)

    def fitted(self, r, t):
        omega, v = se3_log(r, t)
        u = self.first_order(omega, v)
        rows, cols, weights = self.ring
        du, dp = u[rows] - u[cols], self.b0[rows] - self.b0[cols]
        skew = np.array([hat(d) for d in dp])  # ω × dp = −[dp]× ω
        normal = np.zeros((len(u), 3, 3))
        rhs = np.zeros((len(u), 3))
        np.add.at(normal, rows, weights[:, None, None] * np.einsum('kji,kjl->kil', skew, skew))
        np.add.at(rhs, rows, -weights[:, None] * np.einsum('kji,kj->ki', skew, du))
        x = np.empty_like(self.b0)
        for i, p in enumerate(self.b0):
            oi = np.linalg.solve(normal[i], rhs[i])
            ri, ti = se3_exp(oi, u[i] - np.cross(oi, p))
            x[i] = ri @ p + ti
        return self.constrain(x, r, t)

    def lever(self, r, t):
        omega, v = se3_log(r, t)
        blended_first = self.weight[:, None] * (self.b0 @ hat(omega).T + v)
        return self.constrain(self.blended(r, t) + self.first_order(omega, v) - blended_first, r, t)

    def worst_radius_error(self, x):
        worst = 0.0
        for j in range(1, RINGS - 1):
            ring = x[j * AROUND:(j + 1) * AROUND]
            worst = max(worst, abs(np.linalg.norm(ring - ring.mean(0), axis=1).mean() - 1.0))
        return worst


def main():
    s = Study()
    methods = {'linear': s.linear, 'blended': s.blended, 'fitted': s.fitted, 'lever': s.lever}
    print('worst ring |mean radius - 1| at 90°, and the largest distance to linear at small angles')
    print(f'{"method":8} {"twist":>7} {"bend":>7}   {"twist 0.1 / 0.05 rad":>22}   {"bend 0.1 / 0.05 rad":>22}')
    for name, method in methods.items():
        row = [s.worst_radius_error(s.decode(method(*s.motion(kind, np.pi / 2)))) for kind in ('twist', 'bend')]
        small = []
        for kind in ('twist', 'bend'):
            d = [np.abs(method(*s.motion(kind, a)) - s.linear(*s.motion(kind, a))).max() for a in (0.1, 0.05)]
            small.append(f'{d[0]:.1e} / {d[1]:.1e}')
        print(f'{name:8} {row[0]:7.3f} {row[1]:7.3f}   {small[0]:>22}   {small[1]:>22}')


if __name__ == '__main__':
    main()
