"""The unrolled root-free Cholesky solve M a = f (M = L diag(d) Lᵀ), as lines of code."""

from __future__ import annotations


def ldlt_lines(n: int, zero: list[list[bool]], rhs: str = "f", out: str = "a", one: str = "1.0") -> list[str]:
    """Lines solving M a = f, with the entries m{i}_{j} (i ≥ j) and {rhs}{i} given; writes {out}{i}.

    M is symmetric positive definite: no pivoting, n divisions.  ``zero[i][j]``: M_ij
    is structurally zero; an entry of L is zero when M_ij is and no earlier column
    fills it in, and is then skipped.  ``one``: the literal of a reciprocal, "1.0"
    for numba, "1" for code generic over the number type."""
    lz = [[zero[i][j] for j in range(n)] for i in range(n)]  # L_ij structurally zero
    lines = []
    for j in range(n):
        terms = [f" - E{j}_{k}*L{j}_{k}" for k in range(j) if not lz[j][k]]
        lines.append(f"d{j} = m{j}_{j}{''.join(terms)}")
        lines.append(f"r{j} = {one}/d{j}")
        for i in range(j + 1, n):
            fill = [k for k in range(j) if not lz[i][k] and not lz[j][k]]
            if zero[i][j] and not fill:
                lz[i][j] = True
                continue
            lz[i][j] = False
            head = "0" if zero[i][j] else f"m{i}_{j}"
            lines.append(f"E{i}_{j} = {head}{''.join(f' - E{i}_{k}*L{j}_{k}' for k in fill)}")
            lines.append(f"L{i}_{j} = E{i}_{j}*r{j}")
    for i in range(n):  # L y = f
        terms = "".join(f" - L{i}_{k}*y{k}" for k in range(i) if not lz[i][k])
        lines.append(f"y{i} = {rhs}{i}{terms}")
    for i in reversed(range(n)):  # Lᵀ a = diag(d)⁻¹ y
        terms = "".join(f" - L{k}_{i}*{out}{k}" for k in range(i + 1, n) if not lz[k][i])
        lines.append(f"{out}{i} = y{i}*r{i}{terms}")
    return lines
