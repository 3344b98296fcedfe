"""Compiled dispatch on the run's ``kind``: one branch per registered part (variant, law).

``kind`` is a run constant, so a branch on it is perfectly predicted and costs nothing
measurable, while one compiled kernel serves every variant and law (compiling a kernel
per combination is what made a fresh build take most of an hour).
"""
from __future__ import annotations

from . import jitcache  # noqa: F401  (before numba: the kernel cache's folder and locator)
from numba import njit  # noqa: E402


def by_kind(functions: dict, selector: str, arguments: str, takes_kind: bool = False):
    """A compiled ``(kind, arguments) -> functions[selector(kind)](arguments)``.

    ``functions`` maps each value of ``selector`` (an expression in ``kind``, e.g.
    ``"(kind >> 6) & 3"``) to a compiled function; ``arguments`` names their arguments
    (``takes_kind``: the functions take ``kind`` first themselves)."""
    namespace = {f"_{value}": function for value, function in functions.items()}
    values = sorted(functions)
    passed = f"kind, {arguments}" if takes_kind else arguments
    lines = [f"def dispatch(kind, {arguments}):"]
    if len(values) == 1:
        lines.append(f"    return _{values[0]}({passed})")
    else:
        lines.append(f"    chosen = {selector}")
        for i, value in enumerate(values[:-1]):  # one return: numba's inliner wants one
            lines.append(f"    {'if' if i == 0 else 'elif'} chosen == {value}:")
            lines.append(f"        result = _{value}({passed})")
        lines.append("    else:")
        lines.append(f"        result = _{values[-1]}({passed})")
        lines.append("    return result")
    exec("\n".join(lines), namespace)  # noqa: S102 - source built from the registries' integer keys only
    # Inlined into its callers: a call of a separately compiled function would pass its
    # arrays with a reference count taken and dropped per call (where a kernel has not
    # taken their data pointers, ``unowned``), which cost the fixed-step kernels up to 4x.  (numba's SSA check then warns that the branches' shared result
    # is "not in scope"; it is a pedantic warning of numba's own, filtered in jitcache.)
    return njit(inline="always")(namespace["dispatch"])
