"""`curve-vae serve`: run the REST service under uvicorn.

`configure_parser` adds the options to the `serve` subcommand and `run` starts the server.
Every option falls back to its CURVE_VAE_* environment variable, then to the default in
`service.settings.Settings`; a flag given on the command line wins over the environment.
"""

from __future__ import annotations

import argparse
import contextlib
import copy
import json
import logging
import os
import shutil
import signal
import sys
import tempfile
import threading
from collections.abc import Iterator
from typing import Any, Literal, TypedDict, get_origin

from pydantic import ValidationError

from curve_vae.inference.choices import choices
from curve_vae.service.settings import Settings

#: `serve --help`'s groups, by the `flag` each Settings field names (service.settings: EVERYONE, LIMITS, TUNING).
GROUPS = {
    "everyone": "what everyone sets",
    "limits": "limits (what one request may ask; beyond them a 4xx or 5xx that says which)",
    "tuning": "tuning (the defaults suit most machines: measure before changing them, docs/BENCHMARKS.md)",
}


def flagged() -> dict[str, list[str]]:
    """The Settings fields that have a flag, by group, in the order Settings lists them."""
    out: dict[str, list[str]] = {group: [] for group in GROUPS}
    for name, field in Settings.model_fields.items():
        extra = field.json_schema_extra
        if isinstance(extra, dict) and extra.get("flag") in out:
            out[str(extra["flag"])].append(name)
    return out


def _argument(name: str) -> dict[str, Any]:
    """argparse's keywords for a Settings field's flag: its type, choices and help (default and variable appended)."""
    field = Settings.model_fields[name]
    kind = field.annotation if field.annotation in (int, float) else str  # the rest pydantic reads from text
    default = field.get_default(call_default_factory=True)
    default_text = ",".join(default) if isinstance(default, list) else default
    default_text = "none" if default_text in ("", None) else default_text
    values = list(choices(field.annotation)) if get_origin(field.annotation) is Literal else None
    text = f"{field.description} (default: {default_text}; env CURVE_VAE_{name.upper()})"
    return {"dest": name, "type": kind, "default": None, "choices": values, "help": text}


def configure_parser(parser: argparse.ArgumentParser) -> None:
    """Add the serve options to `parser` (the `serve` subcommand's parser): a flag a Settings field that has one."""
    parser.usage = "%(prog)s [--host HOST] [--port PORT] [--model-dir DIR] [--workers N] [options]"
    for group_name, names in flagged().items():
        group = parser.add_argument_group(GROUPS[group_name])
        for name in names:
            flag = "--" + name.replace("_", "-")
            group.add_argument(*([flag, "--model"] if name == "model_dir" else [flag]), **_argument(name))


def settings_from_args(args: argparse.Namespace) -> Settings:
    """Settings from the environment, overridden by the flags that were given."""
    names = [name for group in flagged().values() for name in group]
    overrides = {name: getattr(args, name) for name in names if getattr(args, name, None) is not None}
    return Settings(**overrides)


def _as_env(settings: Settings) -> dict[str, str]:
    out = {}
    for name, value in settings.model_dump().items():
        if value is None:  # unset stays unset (str(None) would be read back as the text "None")
            continue
        out[f"CURVE_VAE_{name.upper()}"] = json.dumps(value) if isinstance(value, list) else str(value)
    return out


def _log_config(level: str) -> dict[str, Any]:
    """uvicorn's logging, with the service's own logger printed like uvicorn's."""
    from uvicorn.config import LOGGING_CONFIG

    config = copy.deepcopy(LOGGING_CONFIG)
    config["loggers"]["service"] = {
        "handlers": ["default"],
        "level": level.upper() if level != "trace" else "DEBUG",
        "propagate": False,
    }
    return config


def where(host: str, port: int) -> str:
    """The startup log's line saying where people find the page, the API docs and the metrics."""
    shown = {"0.0.0.0": "127.0.0.1", "::": "[::1]", "": "127.0.0.1"}.get(host, f"[{host}]" if ":" in host else host)
    base = f"http://{shown}:{port}"
    return f"the page: {base}/ · the API docs: {base}/docs · metrics: {base}/metrics"


def _server_class() -> type:
    import uvicorn

    class Server(uvicorn.Server):
        """uvicorn's server, which once it listens says where the page, the API docs and the metrics are."""

        async def startup(self, sockets: list[Any] | None = None) -> None:
            await super().startup(sockets=sockets)
            if self.started and self.servers and self.config.uds is None and self.config.fd is None:
                port = self.config.port or self.servers[0].sockets[0].getsockname()[1]
                logging.getLogger("uvicorn.error").info(where(self.config.host, port))

    return Server


@contextlib.contextmanager
def _stops_succeed() -> Iterator[None]:
    """A stop by SIGTERM or SIGINT, once in-flight requests have finished, is a success (exit 0). uvicorn hands the
    signal that stopped it, after shutting down, to the handler it found installed (Python's: exit -15 or
    KeyboardInterrupt, which look like a crash to an orchestrator); this one lets it go."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    found = {sig: signal.signal(sig, lambda *_: None) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, handler in found.items():
            signal.signal(sig, handler)


class _ServerOptions(TypedDict):
    """The uvicorn options both ways of starting pass (uvicorn.Config, uvicorn.run)."""

    host: str
    port: int
    log_level: str
    log_config: dict[str, Any]
    access_log: bool


def _run_workers(settings: Settings, common: _ServerOptions) -> None:
    """`settings.workers` processes under uvicorn's supervisor (restarts, SIGHUP, TTIN/TTOU), all accepting from one
    listening socket (uvicorn's `--workers`; docs/DEPLOYMENT.md "Workers" measures it against a socket a worker)."""
    import uvicorn
    from uvicorn.config import STARTUP_FAILURE
    from uvicorn.supervisors import Multiprocess

    # Workers are fresh processes: they rebuild the same settings from the environment.
    os.environ.update(_as_env(settings))
    log = logging.getLogger("uvicorn.error")
    config = uvicorn.Config("curve_vae.service.server:supervised_app", factory=True, workers=settings.workers, **common)
    with _shared_metrics():
        try:
            sock = config.bind_socket()
        except SystemExit:  # uvicorn logged the OSError
            log.error(
                "cannot listen on %s:%d: the address is in use, or not this machine's", settings.host, settings.port
            )
            raise SystemExit(STARTUP_FAILURE) from None
        log.info(where(settings.host, sock.getsockname()[1]))
        supervisor = Multiprocess(config, sockets=[sock])
        try:
            supervisor.run()
        except KeyboardInterrupt:
            pass
        finally:
            sock.close()
        if any(p.exitcode == STARTUP_FAILURE for p in supervisor.processes):
            raise SystemExit(STARTUP_FAILURE)  # uvicorn's supervisor stops, but would exit 0


def _first_worker(supervisor: int) -> bool:
    """Whether this worker is the first of `supervisor`'s to start: it claims a file in the workers' shared
    directory (the Prometheus values'); without one, every worker is the first."""
    from curve_vae.service.metrics import MULTIPROC_DIR

    directory = os.environ.get(MULTIPROC_DIR)
    if not directory:
        return True
    try:
        os.close(os.open(os.path.join(directory, f"started-{supervisor}"), os.O_CREAT | os.O_EXCL | os.O_WRONLY))
    except FileExistsError:
        return False
    except OSError:
        return True
    return True


#: How often a worker looks for its supervisor, seconds.
SUPERVISOR_CHECK_S = 1.0


def supervised_app() -> Any:
    """The app of one of `_run_workers`' worker processes (uvicorn's factory, in the worker), which also stops the
    worker when its supervisor is gone: a supervisor killed outright (SIGKILL, the OOM killer) cannot stop its
    workers, and they would go on holding the port, the model's memory and a share of the connections that no one
    restarts. The worker asks itself to stop (SIGTERM: requests in flight finish) once its parent is another."""
    import time

    from curve_vae.service.app import create_app_from_env

    supervisor = os.getppid()
    if not _first_worker(supervisor):  # the startup log says each thing once: the first worker to start says it
        for name in ("uvicorn.error", "service"):
            logger = logging.getLogger(name)
            if logger.getEffectiveLevel() == logging.INFO:
                logger.setLevel(logging.WARNING)

    def watch() -> None:
        while os.getppid() == supervisor:
            time.sleep(SUPERVISOR_CHECK_S)
        logging.getLogger("uvicorn.error").warning("the supervisor (pid %d) is gone: this worker stops", supervisor)
        os.kill(os.getpid(), signal.SIGTERM)

    threading.Thread(target=watch, name="supervisor-watch", daemon=True).start()
    return create_app_from_env()


def _shared_metrics() -> contextlib.AbstractContextManager[None]:
    """A fresh directory where the workers keep their Prometheus values, so that a scrape of any one of them
    answers for all (service.metrics); removed when the server stops. One set in the environment is used as it is
    (the operator's, who then empties it between runs, as prometheus-client asks)."""
    from curve_vae.service.metrics import MULTIPROC_DIR

    if os.environ.get(MULTIPROC_DIR):
        return contextlib.nullcontext()
    return _env_directory(MULTIPROC_DIR, "curve-vae-metrics-")


@contextlib.contextmanager
def _env_directory(name: str, prefix: str) -> Iterator[None]:
    """A fresh directory, named by environment variable `name` for the workers to inherit, removed (and the variable
    unset) when the server stops."""
    path = tempfile.mkdtemp(prefix=prefix)
    os.environ[name] = path
    try:
        yield
    finally:
        os.environ.pop(name, None)
        shutil.rmtree(path, ignore_errors=True)


def run(args: argparse.Namespace) -> int:
    """Start the server; returns the exit status (2: bad configuration, 3: the app failed to start)."""
    import uvicorn

    from curve_vae.inference.model.cpus import worker_count
    from curve_vae.inference.model.manifest import Manifest, ModelLoadError
    from curve_vae.inference.model.sessions import resolve_providers

    try:
        settings = settings_from_args(args)
    except ValidationError as e:
        problems = "; ".join(f"{'.'.join(map(str, err['loc']))}: {err['msg']}" for err in e.errors())
        print(f"curve-vae serve: error: {problems}", file=sys.stderr)
        return 2
    try:  # the clear, early form of the errors the workers would hit at startup
        Manifest.read(settings.model_dir)
        resolve_providers(settings.providers)
    except ModelLoadError as e:
        print(f"curve-vae serve: error: {e}", file=sys.stderr)
        return 2
    if settings.kernel_cache_seed is not None:  # before the workers start: they load what it holds
        from curve_vae.inference.model.opening import seed_kernel_cache

        seeded = seed_kernel_cache(settings.kernel_cache_seed)
        if seeded:
            logging.getLogger("service").info("%s", seeded)
    common = _ServerOptions(
        host=settings.host,
        port=settings.port,
        log_level=settings.log_level,
        log_config=_log_config(settings.log_level),
        access_log=settings.access_log,
    )
    try:
        workers = worker_count(settings)
        if workers == 1:
            from curve_vae.service.app import create_app

            config = uvicorn.Config(create_app(settings), **common)
            server = _server_class()(config)
            with _stops_succeed():
                server.run()
            if not server.started:
                return 3  # the app failed to start (uvicorn's own code for it)
        else:  # the workers rebuild the settings from the environment: the count they are, not 0
            _run_workers(settings.model_copy(update={"workers": workers}), common)
    except SystemExit as e:  # uvicorn exits 3 when the app fails to start
        return e.code if isinstance(e.code, int) else 1
    return 0


def main(argv: list[str] | None = None) -> int:
    """`python -m curve_vae.service.server`: the same as `curve-vae serve`."""
    parser = argparse.ArgumentParser(prog="curve-vae serve", description="Serve the curve VAE over REST.")
    configure_parser(parser)
    return run(parser.parse_args(argv))


if __name__ == "__main__":
    sys.exit(main())
