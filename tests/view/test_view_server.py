"""The view's viewer server and recording stream: where they listen, and what they refuse."""

from __future__ import annotations

import socket
import urllib.request

import pytest

pytest.importorskip("rerun")

from pycram.trace.view.server import ViewError, ViewerServer  # noqa: E402
from pycram.trace.view.session import ViewSession  # noqa: E402


def test_the_server_serves_the_web_viewer_on_loopback_only():
    with ViewerServer(port=0) as server:
        assert server.running and server.port > 0 and server.grpc_port > 0
        assert server.url.startswith(f"http://127.0.0.1:{server.port}/?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A")
        assert server.grpc_url == f"rerun+http://127.0.0.1:{server.grpc_port}/proxy"
        page = urllib.request.urlopen(f"http://127.0.0.1:{server.port}/", timeout=30).read()
        assert b"Rerun" in page and b"re_viewer.js" in page  # the web viewer, served from this machine
        wasm = urllib.request.urlopen(f"http://127.0.0.1:{server.port}/re_viewer_bg.wasm", timeout=60).read()
        assert wasm[:4] == b"\0asm"
        import psutil

        viewer = psutil.Process(server.pid)  # (not every child of this process: a roscore of
        # another test listens on every interface)
        listening = {
            c.laddr.ip
            for p in [viewer, *viewer.children(recursive=True)]
            for c in p.net_connections(kind="tcp")
            if c.status == psutil.CONN_LISTEN
        }
        assert listening  # the viewer's own sockets were found
        assert listening == {"127.0.0.1"}
    assert not server.running


def test_a_port_in_use_is_refused_with_what_to_try():
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        with pytest.raises(ViewError, match=r"port in use\? try another --view-port.*Address already in use"):
            ViewerServer(port=port).start(timeout=30)


def test_bad_ports_and_missing_recordings_are_refused():
    with pytest.raises(ViewError, match="0..65535"):
        ViewerServer(port=70000)
    with pytest.raises(ViewError, match="no recording at"):
        ViewerServer(files=["/nonexistent/run.rrd"])


def test_a_session_needs_somewhere_to_go_and_a_positive_rate(tmp_path):
    with pytest.raises(ValueError, match="an .rrd file"):
        ViewSession()
    with pytest.raises(ValueError, match="world_rate_hz"):
        ViewSession(rrd=tmp_path / "x.rrd", world_rate_hz=0)


def test_a_session_without_a_world_logs_the_task_tree(tmp_path):
    """A plan with no simulated robot: the view has the tree (one row per status change) and the
    log, and no world."""
    import logging

    from pycram.language import par, seq
    from pycram.trace.view.rrd import RecordingContents

    session = ViewSession(rrd=tmp_path / "run.rrd").start()
    try:
        seq(lambda: None, lambda: par(lambda: None, lambda: None))
        logging.getLogger("pycram.test").warning("a line of the run's log")
    finally:
        path = session.close()
    contents = RecordingContents.read(path)
    assert contents.rows["/tree/status"] == session.counts["task status"] >= 2 * 5
    assert contents.rows["/log"] == 1
    assert not contents.has("/truth")
    assert session.close() == path  # idempotent


def test_an_experiment_worker_views_only_the_run_it_was_asked_for(monkeypatch):
    import inspect

    from pycram.trace.view.session import VIEW_CONNECT_ENV, VIEW_RUN_ENV, viewed_run

    def scenario(robot, seed, faults=frozenset(), db_url=None, pictures=False, stepping="lockstep"):
        return {"robot": robot, "seed": seed}

    monkeypatch.delenv(VIEW_CONNECT_ENV, raising=False)
    monkeypatch.delenv(VIEW_RUN_ENV, raising=False)
    assert viewed_run(scenario, "pr2", 2) is scenario  # no viewer asked for
    monkeypatch.setenv(VIEW_CONNECT_ENV, "rerun+http://127.0.0.1:1/proxy")
    monkeypatch.setenv(VIEW_RUN_ENV, "pr2:2")
    assert viewed_run(scenario, "pr2", 3) is scenario
    assert viewed_run(scenario, "tiago", 2) is scenario
    wrapped = viewed_run(scenario, "pr2", 2)
    assert wrapped is not scenario
    assert inspect.signature(wrapped) == inspect.signature(scenario)  # the runner reads its keywords
    monkeypatch.setenv(VIEW_RUN_ENV, ":2")  # the seed alone: every robot's run of it
    assert viewed_run(scenario, "tiago", 2) is not scenario
