"""``mocycle studio``: the local web application (library, review, authoring plane)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .. import tasks
from ..errors import MocycleError
from .common import app, err, escape, friendly, out


def serve(application, host: str, port: int, open_browser: bool, ready=None) -> None:
    """Run ``application`` with uvicorn on ``host:port`` (0: a free port); print the address, open it."""
    import socket
    import threading
    import webbrowser

    import uvicorn

    sock = socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((host, port))
        sock.listen(128)  # connections wait in the queue until uvicorn serves them
    except OSError as exc:
        raise MocycleError(f"cannot listen on {host}:{port}: {exc.strerror or exc}") from None
    port = sock.getsockname()[1]
    url = f"http://{host if ':' not in host else f'[{host}]'}:{port}/"
    access = getattr(application.state, "access", None)
    if access is not None:
        access.bind(host, port)  # the Host the server answers for (and whether it serves the network)
        if access.remote:  # every request needs the token: the URL carries it
            url += f"?token={access.token}"
            err.print(f"warning: --host {host} serves your motion library to the network (every machine that "
                      "can reach this one); only the URL below, which carries the server's token, opens it",
                      soft_wrap=True, markup=False)
    from ..studio.server import config

    # slow request heads closed, connections bounded, a stop that waits for nobody for long (studio/server.py)
    server = uvicorn.Server(config(application, log_level="warning", lifespan="on"))
    out.print(f"mocycle studio on {escape(url)} (Ctrl-C to stop)", soft_wrap=True)
    if open_browser:
        threading.Timer(0.8, webbrowser.open, (url,)).start()
    if ready is not None:
        ready(url)
    server.run(sockets=[sock])


@app.command()
@friendly
def studio(
    paths: Annotated[list[Path], typer.Argument(help="Motion files (.bvh, .amc) or folders of them.")],
    host: Annotated[str, typer.Option(help="Address to listen on (127.0.0.1: this machine only; any other address "
                                            "serves the network, prints a warning and needs the printed URL's "
                                            "token).")] = "127.0.0.1",
    port: Annotated[int, typer.Option(help="Port to listen on (0: any free port).", min=0, max=65535)] = 8765,
    no_browser: Annotated[bool, typer.Option("--no-browser", help="Do not open a browser.")] = False,
    amc_fps: Annotated[float, typer.Option(help="Frame rate of AMC input files (CMU: 120).")] = tasks.AMC_FPS,
):
    """Review loops on a library of takes and author new motion on the spatial-keyframe plane, in the browser.

    Starts a local web server; the page lists the takes (analysed in the background), plays each take beside its
    loop, and lets you draw new animation on the 2-D plane of its poses (thesis 002, chapter 6).
    """
    try:
        from ..studio.app import create_app
    except ImportError as exc:
        err.print(f"error: the studio needs {exc.name}: pip install 'mocycle[studio]'", soft_wrap=True)
        raise typer.Exit(1) from None
    studio_app = create_app(paths, amc_fps=amc_fps)
    if not studio_app.state.studio.takes:
        raise MocycleError(f"no motion files (.bvh, .amc, .fbx, .glb, .gltf) in {', '.join(map(str, paths))}")
    serve(studio_app, host, port, not no_browser)
