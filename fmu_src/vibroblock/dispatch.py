"""Compiled dispatch on the run's ``kind``: one branch per registered part (variant, law).

``kind`` is a run constant, so a branch on it is perfectly predicted and costs nothing
measurable, while one compiled kernel serves every variant and law (compiling a kernel
per combination is what made a fresh build take most of an hour).
"""
from __future__ import annotations

from . import jitcache  # noqa: F401  (before numba: the kernel cache's folder and locator)
from numba import njit  # noqa: E402


def by_kind(functions: dict, selector: str, arguments: str, takes_kind: bool = False, inline_default_only=False):
    """A compiled ``(kind, arguments) -> functions[selector(kind)](arguments)``.

    ``functions`` maps each value of ``selector`` (an expression in ``kind``, e.g.
    ``"(kind >> 6) & 3"``) to a compiled function; ``arguments`` names their arguments
    (``takes_kind``: the functions take ``kind`` first themselves).  With
    ``inline_default_only`` only the branch of value 0 (a law axis' default) is inlined;
    the others are called, each compiled once as a function of its own (``called``)."""
    # Values sharing one function (e.g. every friction law's spring force) share one branch:
    # each branch is inlined at every call site, and LLVM's time grows with the inlined size.
    groups: dict[int, list[int]] = {}
    for value in sorted(functions):
        groups.setdefault(id(functions[value]), []).append(value)
    branches = sorted(groups.values())
    namespace = {f"_{values[0]}": functions[values[0]] for values in branches}
    passed = f"kind, {arguments}" if takes_kind else arguments
    if inline_default_only:
        for values in branches:
            if 0 not in values:
                namespace[f"_{values[0]}"] = called(functions[values[0]], passed)
    lines = [f"def dispatch(kind, {arguments}):"]
    if len(branches) == 1:
        lines.append(f"    return _{branches[0][0]}({passed})")
    else:
        lines.append(f"    chosen = {selector}")
        for i, values in enumerate(branches[:-1]):  # one return: numba's inliner wants one
            test = " or ".join(f"chosen == {value}" for value in values)
            lines.append(f"    {'if' if i == 0 else 'elif'} {test}:")
            lines.append(f"        result = _{values[0]}({passed})")
        lines.append("    else:")
        lines.append(f"        result = _{branches[-1][0]}({passed})")
        lines.append("    return result")
    exec("\n".join(lines), namespace)  # noqa: S102 - source built from the registries' integer keys only
    # Inlined into its callers: a call of a separately compiled function would pass its
    # arrays with a reference count taken and dropped per call (where a kernel has not
    # taken their data pointers, ``unowned``), which cost the fixed-step kernels up to 4x.  (numba's SSA check then warns that the branches' shared result
    # is "not in scope"; it is a pedantic warning of numba's own, filtered in jitcache.)
    return njit(inline="always")(namespace["dispatch"])


def called(function, arguments: str):
    """``function`` (inlined where it is called) wrapped in a function of ``arguments``
    that is compiled once per signature and called: a law other than an axis' default
    (and a fixed-step scheme's heavier step, ``fixed_step.register``) costs a call where
    it runs, and every kernel that dispatches on the axis stays small for LLVM, whose
    time grows faster than the inlined size (inlined, every law of every axis went into
    every fixed-step loop and doubled its compile time)."""
    namespace = {"function": function}
    exec(f"def called({arguments}):\n    return function({arguments})", namespace)  # noqa: S102 - our own names
    return njit(namespace["called"])
