"""The FMUs' own documentation (FMI 2.0, section 2.3), generated at build time.

``documentation/index.html``: the model's equations, its parameters with units and
defaults, inputs and outputs, integrators, formulations (scene options, initial
states), and how the FMU finds its Python environment; from the same tables the README
is generated from (``vibroblock.parameters``, ``vibroblock.interface``,
``vibroblock.excitation``).  ``model.png``: an icon drawn with matplotlib.

Both are byte-reproducible: no dates, fixed sizes, PNG written without metadata.
"""
from __future__ import annotations

import html
import io

ENV_VARIABLE = "VIBROBLOCK_PYTHON"  # build/python_runtime.c

STYLE = """body{font-family:sans-serif;max-width:60em;margin:2em auto;line-height:1.45}
table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:2px 6px;vertical-align:top;text-align:left}
code,pre{background:#f4f4f4}pre{padding:.6em}"""

EQUATIONS = """<p>A point block of mass <code>m</code> at <code>r = (x, z)</code> is pulled by a spring
<code>k_d</code> whose far end moves at <code>V_d</code>, over a plate that moves vertically.
Newton's law in fixed axes, <code>m r'' = sum F</code>, with the unit tangent
<code>t = (cos a, sin a)</code> and normal <code>n = (-sin a, cos a)</code> of the surface under the
block (<code>a = arctan dZ_p/dx</code>):</p>
<table><tr><th>force</th><th>expression</th><th>active</th></tr>
<tr><td>drive spring</td><td><code>(-k_d (x - V_d t), 0)</code></td><td>always</td></tr>
{load}
<tr><td>normal contact</td><td><code>N n</code>, <code>N = k_n delta - gamma_n u_n</code></td><td>delta &gt; 0</td></tr>
<tr><td>tangential spring</td><td><code>-k_t F t</code></td><td>delta &gt; 0</td></tr>
<tr><td>tangential damping</td><td><code>-gamma_t u_t t</code></td><td>always</td></tr></table>
<ul>
<li>Plate: <code>Z_p(x, t) = A sin(omega t) + plate_z(t){surface}</code>, moving vertically with
<code>V_p = dZ_p/dt</code>; between communication points the external plate follows
<code>plate_z + plate_v tau + plate_a tau^2/2</code>.</li>
<li>Penetration along the normal <code>delta = (Z_p - z) cos a</code>; velocities relative to the
plate <code>u_n = (r' - V_p e_z) . n</code>, <code>u_t = (r' - V_p e_z) . t</code>.</li>
<li>Friction (Cundall-Strack): <code>dF/dt = u_t</code> while <code>delta &gt; 0</code>; <code>F = 0</code> out of
contact and whenever <code>|k_t F| &gt;= mu_s N</code> (a Coulomb reset, counted in
<code>coulomb_resets</code>; <code>slip_count</code> is its old name, kept for one release). A slip of
the block holds many resets: slips are counted from the motion, not by the FMU.</li>
<li>Units: <code>m = g = k_n = 1</code>; lengths in <code>delta_0 = m g / k_n</code>, times in
<code>tau_0 = sqrt(m / k_n)</code>. Source: F. Giacco, E. Lippiello, M. Pica Ciamarra,
<i>Solid-on-solid single block dynamics under mechanical vibration</i>.</li>
</ul>"""

LOADS = {
    "A": "<tr><td>load</td><td><code>(0, -m g)</code></td><td>always</td></tr>",
    "B": "<tr><td>load</td><td><code>(0, -m g)</code></td><td>always</td></tr>",
    "C": "<tr><td>load</td><td><code>-P_l n</code> (normal to the surface)</td><td>always</td></tr>",
}

PYTHON_SECTION = """<h2>Running the FMU: its Python environment</h2>
<p>The model runs in Python (pythonfmu) with numpy and numba. In a Python host (fmpy,
libcosimpy) the host's Python is used and needs those packages. In any other host
(OMSimulator, Simulink, a C or C++ master) the FMU's binary loads and starts a Python
itself, from the first of:</p>
<ol><li>the environment variable <code>{env}</code>: a Python environment's folder or its
<code>bin/python</code>;</li>
<li>the file <code>vibroblock-python.txt</code> in the FMU's top folder (next to
<code>modelDescription.xml</code>);</li>
<li>the file <code>~/.config/vibroblock/python.txt</code> (<code>$XDG_CONFIG_HOME</code> if set);</li>
<li><code>resources/python-environment.txt</code>: the environment the FMU was built with.</li></ol>
<p>A file holds <code>python = /path/to/environment</code> and optionally
<code>library = /path/to/libpython3.X.so</code> (otherwise looked for next to the base
interpreter and in the system's library folders; the Python must be built with a shared
library, as system Pythons and pyenv's with <code>--enable-shared</code> are). If none is
usable, <code>fmi2Instantiate</code> returns NULL and the log says what is missing.</p>
<p>Compiled kernels: the FMU ships numba's compiled kernels for the CPU it was built on
(<code>resources/vibroblock_kernels</code>); they are copied into the numba cache
(<code>NUMBA_CACHE_DIR</code>, default <code>~/.cache/vibroblock/numba</code>) and recompiled only
when numba, Python or the CPU differ (about half a minute, once).</p>
<p>In a non-Python host the binary calls the model's <code>do_step</code> itself for
<code>fmi2DoStep</code> (the most frequent call; pythonfmu handles every other call on the
same instance). Setting the environment variable <code>VIBROBLOCK_PYTHONFMU_DOSTEP=1</code>
sends <code>fmi2DoStep</code> through pythonfmu as well (same results, about 0.4 &micro;s
more per call).</p>"""


def _e(text) -> str:
    return html.escape(str(text))


def _table(header, rows) -> str:
    head = "".join(f"<th>{_e(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{cell}</td>" for cell in row) + "</tr>" for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def _integrators() -> list[tuple[str, str]]:
    """(name (id), description) from the integrator registry and each integrator's module."""
    import sys as _sys

    from vibroblock.integrators import INTEGRATOR_RECORDS

    found = []
    for record in INTEGRATOR_RECORDS.values():
        module = _sys.modules.get(record.advance.py_func.__module__ if record.scheme is None
                                  else record.scheme[1].py_func.__module__)
        doc = (module.__doc__ or "").split("\n\n")
        detail = " ".join(doc[1].split()) if len(doc) > 1 else ""
        found.append((f"<code>{record.name}</code> ({record.id})", _e(f"{record.summary}. {detail}".strip())))
    return found


def block_html(model: str, identifier: str) -> str:
    from vibroblock.interface import DEFAULT_INTEGRATOR_ID, DEFAULT_INTEGRATOR_TEXT, ENERGY_BALANCE, INPUTS, OUTPUTS
    from vibroblock.models import DESCRIPTIONS, defaults, offered_by, parameters_for
    from vibroblock.parameters import INITIAL_STATES, SCENE_OPTIONS

    values = defaults(model)
    rows = [(f"<code>{_e(p.name)}</code>", _e(p.unit), f"{values[p.name]:g}",
             "tunable" if p.tunable else "fixed", _e(p.description)) for p in parameters_for(model)]
    integrators = _integrators()
    options = [("<code>integrator</code>", "Integer", str(DEFAULT_INTEGRATOR_ID), "fixed",
                f"see Integrators; {_e(DEFAULT_INTEGRATOR_TEXT)}"),
               ("<code>initial_state</code>", "Integer", "0", "fixed",
                "<br>".join(f"{i} = {_e(text)}" for i, text in INITIAL_STATES.items())),
               ("<code>energy_balance</code>", "Boolean", "false", "fixed", _e(ENERGY_BALANCE))]
    options += [(f"<code>{_e(name)}</code>", "Boolean", "false", "fixed", _e(text))
                for name, (models, text) in SCENE_OPTIONS.items() if model in offered_by(models)]
    inputs = [(f"<code>{_e(n)}</code>", _e(unit), "0", _e(text)) for n, (unit, text) in INPUTS.items()]
    outputs = [(f"<code>{_e(n)}</code>", kind, _e(unit), _e(text)) for n, (kind, unit, text) in OUTPUTS.items()]
    surface = {"A": "", "B": " + A_x sin(omega_x x)", "C": " + A_x sin(omega_x x)"}.get(
        model, f" + height(x) (vibroblock/models/model_{model.lower()}.py)")
    load = LOADS.get(model, f"<tr><td>load</td><td>as stated in <code>vibroblock/models/model_{model.lower()}.py"
                            "</code></td><td>always</td></tr>")
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{identifier}</title><style>{STYLE}</style></head>
<body><h1>{identifier}: {_e(DESCRIPTIONS[model])}</h1>
<p>Spring-block friction on a vibrating plate, FMI 2.0 co-simulation. Model {model}.</p>
<h2>Equations</h2>
{EQUATIONS.replace("{load}", load).replace("{surface}", surface)}
<h2>Parameters</h2>
{_table(("name", "unit", "default", "variability", "meaning"), rows)}
<p>Bad values (non-finite, non-physical, an unstable <code>dt</code>) are refused with
<code>fmi2Error</code> and a message in the log; the FMU keeps its last good state.</p>
<h2>Integrators and formulations</h2>
{_table(("integrator (value)", "scheme"), integrators)}
<h3>Options</h3>
{_table(("name", "type", "default", "variability", "meaning"), options)}
<h2>Inputs</h2>
{_table(("name", "unit", "start", "meaning"), inputs)}
<h2>Outputs</h2>
{_table(("name", "type", "unit", "meaning"), outputs)}
<p>Any communication step works: the FMU sub-steps on its fixed grid <code>t0 + n dt</code>.
FMU state get/set and serialization restore a run bit for bit.</p>
{PYTHON_SECTION.replace("{env}", ENV_VARIABLE)}
</body></html>
"""


def excitation_html(identifier: str) -> str:
    from vibroblock.excitation import MODES, PARAMETERS

    rows = [(f"<code>{_e(p.name)}</code>", _e(p.unit), f"{p.default:g}", _e(p.description)) for p in PARAMETERS]
    modes = "<br>".join(f"{number} = {_e(name)}" for number, name in MODES.items())
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{identifier}</title><style>{STYLE}</style></head>
<body><h1>{identifier}: vertical plate motion</h1>
<p>Outputs <code>plate_z</code>, <code>plate_v = d plate_z/dt</code> and
<code>plate_a = d plate_v/dt</code> (exact derivatives of each other) for the plate inputs of the
Block FMUs: <code>plate_z = amplitude_scale * w(s) * f(s)</code> with signal time
<code>s = (t - onset)/time_scale</code> and a start ramp <code>w</code> over <code>ramp_time</code>.</p>
<h2>Signals (<code>mode</code>)</h2><p>{modes}</p>
<ul><li>harmonic: <code>f = amplitude sin(omega s + phase)</code>;</li>
<li>linear / logarithmic chirp: frequency from <code>omega_start</code> to <code>omega_end</code> over
<code>sweep_time</code>;</li>
<li>sum of harmonics <code>amplitude_i sin(omega_i s + phase_i)</code>, i = 1..4;</li>
<li>playback of the record in <code>record_file</code> (or the bundled one): piecewise-linear
acceleration integrated exactly, at rest outside the record.</li></ul>
<h2>Parameters</h2>
{_table(("name", "unit", "default", "meaning"), rows)}
<p><code>record_file</code> (String): a <code>.npz</code> or two-column text record, or a seismic record in
any format obspy reads (MiniSEED, SAC, GSE2, ..., PEER <code>.AT2</code>), processed at initialization to
consistent SI motion (response removed with <code>record_inventory</code>, a StationXML, RESP or dataless
SEED file, for a record in counts); empty for the bundled record.</p>
{PYTHON_SECTION.replace("{env}", ENV_VARIABLE)}
</body></html>
"""


CHAIN_SIZES = {False: "Per-block outputs <code>x[i]</code>, <code>vx[i]</code>, i = 1..N, N fixed when the FMU "
                      "was built.",
               True: "Per-block outputs: the FMI 3.0 arrays <code>x</code> and <code>vx</code> of size <code>N</code>, "
                     "a structural parameter (UInt64, default 16, 1 to 10000) that a master sets before the other "
                     "settings, in configuration mode or before initialization."}
FMI3_HOST_SECTION = """<h2>Host</h2>
<p>pythonfmu3's native library runs the model in the host process's own Python, which must offer
numpy, numba and pythonfmu (fmpy started from the environment the FMU was built with does). A
refused setting is logged with status fmi3Error; pythonfmu3 returns fmi3OK from setters, so the FMU
then refuses to initialize and every doStep returns fmi3Error. The start time is 0: pythonfmu3 does
not pass fmi3EnterInitializationMode's start time on, and a doStep from another time is refused.</p>"""


def chain_html(identifier: str, arrays: bool = False) -> str:
    from vibroblock.chain.runner import BLOCK_DEFAULTS, CHAIN_PARAMETERS, chain_defaults
    from vibroblock.chain.slave import AGGREGATES, BLOCK_PARAMETERS, CATALOG_TEXT
    from vibroblock.models import defaults, parameters_for

    specs, values = {p.name: p for p in parameters_for("A")}, {**defaults("A"), **BLOCK_DEFAULTS}
    rows = [(f"<code>{'k_p' if n == 'k_d' else n}</code>", _e(specs[n].unit), f"{values[n]:g}",
             _e(specs[n].description)) for n in BLOCK_PARAMETERS]
    rows += [(f"<code>{n}</code>", _e(unit), f"{chain_defaults()[n]:g}", _e(text))
             for n, (_, unit, text) in CHAIN_PARAMETERS.items()]
    outputs = [(f"<code>{n}</code>", _e(unit), _e(text)) for n, (_, unit, text) in AGGREGATES.items()]
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{identifier}</title><style>{STYLE}</style></head>
<body><h1>{identifier}: a chain of blocks on a vibrating plate</h1>
<p>N blocks in a row (Burridge-Knopoff), each a model-A block with the single block's contact and
friction laws and its symplectic Euler step; a leaf spring <code>k_p</code> pulls each towards the
loader at <code>V_d t</code>, springs <code>k_c</code> couple neighbours (free or periodic ends).
{CHAIN_SIZES[arrays]}</p>
<h2>Parameters</h2>
{_table(("name", "unit", "default", "meaning"), rows)}
<p><code>catalog_file</code> (String): {_e(CATALOG_TEXT)}.</p>
<h2>Outputs</h2>
{_table(("name", "unit", "meaning"), outputs)}
{FMI3_HOST_SECTION if arrays else PYTHON_SECTION.replace("{env}", ENV_VARIABLE)}
</body></html>
"""


def icon_png(model: str | None) -> bytes:
    """A 128 x 128 icon: the block on its plate with the drive spring, or a chirp."""
    import matplotlib

    matplotlib.use("Agg")
    import numpy as np
    from matplotlib.figure import Figure

    with matplotlib.rc_context({"svg.hashsalt": "vibroblock", "path.simplify": False}):
        fig = Figure(figsize=(1.28, 1.28), dpi=100)
        ax = fig.add_axes((0, 0, 1, 1))
        ax.set_xlim(0, 10)
        ax.set_ylim(0, 10)
        ax.axis("off")
        x = np.linspace(0, 10, 200)
        if model is None:
            ax.plot(x, 5 + 3 * np.sin(0.15 * x ** 2) * np.exp(-0.05 * x), color="#1f5fa8", lw=2.5)
        else:
            ripple = 0.0 if model == "A" else 0.8
            plate = 3 + ripple * np.sin(1.6 * x)
            ax.fill_between(x, 0.6, plate, color="#8c8c8c")
            top = 3 + ripple * np.sin(1.6 * 4.0)
            ax.add_patch(matplotlib.patches.Rectangle((3.0, top), 2.0, 2.0, color="#c0392b"))
            spring = np.linspace(5.0, 9.2, 40)
            ax.plot(spring, top + 1 + 0.35 * np.sign(np.sin(np.linspace(0, 8 * np.pi, 40))), color="k", lw=1.2)
            ax.annotate("", xy=(1.2, 1.0), xytext=(1.2, 2.6), arrowprops={"arrowstyle": "<->", "lw": 1.5})
            if model == "C":
                ax.annotate("", xy=(4.0, top + 2.0), xytext=(4.0, top + 4.2), arrowprops={"arrowstyle": "->", "lw": 2})
            ax.text(8.6, 8.0, model, fontsize=16, ha="center", va="center", weight="bold")
        buffer = io.BytesIO()
        fig.savefig(buffer, format="png", metadata={"Software": None})
    return buffer.getvalue()


def archive_members(name: str) -> dict[str, bytes]:
    """``documentation/index.html`` and ``model.png`` for the FMU ``name``."""
    if name in ("BlockChain", "BlockChain3"):
        model = "A"
        page = chain_html(name, arrays=name == "BlockChain3")
    elif name.startswith("Block"):
        model = name[len("Block"):]
        page = block_html(model, name)
    else:
        model = None
        page = excitation_html(name)
    return {"documentation/index.html": page.encode(), "model.png": icon_png(model)}
