"""Record meshcat commands in memory and write them out as one self-contained HTML page.

``meshcat.Visualizer`` normally talks over ZeroMQ to a ``meshcat-server``
subprocess, and ``Visualizer.static_html()`` asks that server for the page.  The
server only stores the packed commands it has seen and pastes them, base64
encoded, under the bundled three.js viewer (``meshcat/viewer/dist/main.min.js``).
``SceneRecorder`` does the same without any server, socket or subprocess: it is
a drop-in ``window`` for ``meshcat.Visualizer(window=...)``, so the usual
meshcat (and Pinocchio ``MeshcatVisualizer``) calls work unchanged, and nothing
is started that could be left behind.

Differences from meshcat's own static HTML, both deliberate:

* commands are replayed *synchronously and in order* (meshcat's page issues one
  ``fetch`` per command, which may resolve out of order);
* floats are packed as float32 (``umsgpack`` ``force_float_precision``), which
  halves the size of the animation keys; display needs no more precision.

A command that repeats an earlier one (same kind, path and property) replaces
it in place, as the server's scene tree does, so no object is sent twice.
"""

from __future__ import annotations

import base64
import html
from importlib.resources import files

import meshcat
import umsgpack

VIEWER_JS = files("meshcat") / "viewer" / "dist" / "main.min.js"

_PAGE = """<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{title}</title>
<style>
body {{ margin: 0; overflow: hidden; font-family: sans-serif; }}
#meshcat-pane {{ width: 100vw; height: 100vh; overflow: hidden; }}
#overlay {{ position: absolute; left: 10px; bottom: 8px; color: #222; font-size: 14px;
  pointer-events: none; white-space: pre; }}
</style>
</head>
<body>
<div id="meshcat-pane"></div>
<div id="overlay">{caption}<span id="clock"></span></div>
<script>
{viewer_js}
</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
(function () {{
  var commands = {commands};
  for (var i = 0; i < commands.length; i++) {{
    var bin = atob(commands[i]);
    var bytes = new Uint8Array(bin.length);
    for (var j = 0; j < bin.length; j++) bytes[j] = bin.charCodeAt(j);
    viewer.handle_command_bytearray(bytes);
  }}
  var clock = document.getElementById("clock");
  function tick() {{
    var actions = viewer.animator.actions;
    if (actions.length) {{
      var t = actions.reduce(function (a, b) {{ return Math.max(a, b.time); }}, 0);
      clock.textContent = "  t = " + t.toFixed(2) + " s";
    }}
    requestAnimationFrame(tick);
  }}
  tick();
}})();
</script>
</body>
</html>
"""


class SceneRecorder:
    """A meshcat ``window`` that keeps the packed commands instead of sending them."""

    def __init__(self) -> None:
        self._commands: list[bytes] = []
        self._index: dict[tuple[str, str, str], int] = {}

    def send(self, command) -> None:
        """Pack a meshcat command (``SetObject``, ``SetTransform``, ...) and keep it."""
        data = command.lower()
        key = (data["type"], data["path"], str(data.get("property", "")))
        packed = umsgpack.packb(data, force_float_precision="single")
        if data["type"] == "delete" or key not in self._index:
            self._index[key] = len(self._commands)
            self._commands.append(packed)
        else:
            self._commands[self._index[key]] = packed

    def visualizer(self) -> meshcat.Visualizer:
        """A ``meshcat.Visualizer`` that records into this object; no server is started."""
        return meshcat.Visualizer(window=self)

    @property
    def commands(self) -> list[bytes]:
        return list(self._commands)

    def html(self, title: str, caption: str = "") -> str:
        """The self-contained page: viewer bundle, then every command in order.

        ``title`` and ``caption`` are escaped here; pass them as plain text.
        """
        encoded = ",\n".join(f'"{base64.b64encode(c).decode("ascii")}"' for c in self._commands)
        return _PAGE.format(
            title=html.escape(title),
            caption=html.escape(caption),
            viewer_js=VIEWER_JS.read_text(encoding="utf-8"),
            commands=f"[\n{encoded}\n]",
        )
