"""Connecting to a Dask scheduler: the address a user typed, checked, and a client made
within a deadline whatever listens there (:func:`connect_client`), for a sweep's
:class:`~nylonflex.engine.cluster.DaskExecutor` and ``verify --scheduler``."""

from __future__ import annotations

import contextlib
import re
import threading

from ..units import InputError

__all__ = ["CONNECT_TIMEOUT", "connect_client"]

#: Seconds to wait for the scheduler to answer before refusing the address.
CONNECT_TIMEOUT = 5.0

_ADDRESS = re.compile(r"^(?:(tcp|tls|ws|wss)://)?(\[[0-9a-fA-F:.]+\]|[A-Za-z0-9_.-]+):"
                      r"([0-9]{1,5})$")


def _normalise_address(address) -> str:
    """``tcp://HOST:PORT`` from what the user gave; refuse anything else in one line."""
    if hasattr(address, "scheduler_address"):  # a LocalCluster, SLURMCluster, ...
        address = address.scheduler_address
    text = str(address).strip()
    m = _ADDRESS.match(text)
    if not m or not 0 < int(m.group(3)) < 65536:
        raise InputError(f"--scheduler: expected a Dask scheduler address such as "
                         f"tcp://HOST:8786, got {text!r}")
    return f"{m.group(1) or 'tcp'}://{m.group(2)}:{int(m.group(3))}"


def _connect(client_class, address, timeout):
    """A Client of ``address`` within ``timeout`` seconds, whatever listens there.

    Dask's own connect timeout does not cover a listener that accepts and never answers
    (a web server, the dashboard port typed for the scheduler's): its handshake waits
    forever. The client is made in a daemon thread, which is abandoned after the deadline.
    """
    box: dict = {}

    def connect():
        try:
            box["client"] = client_class(address, timeout=timeout, set_as_default=False)
        except BaseException as exc:  # noqa: BLE001 - handed to the caller's thread
            box["error"] = exc
            _disarm(exc, client_class)

    thread = threading.Thread(target=connect, name="nylonflex-connect", daemon=True)
    thread.start()
    thread.join(timeout + 1.0)
    if thread.is_alive():
        raise TimeoutError("no answer")
    if "error" in box:
        raise box["error"]
    return box["client"]


def connect_client(client_class, address, timeout: float = CONNECT_TIMEOUT):
    """A Dask ``Client`` (``client_class``, None for distributed's) of the scheduler at
    ``address`` (``tcp://HOST:PORT``, ``HOST:PORT`` or a cluster object), within
    ``timeout`` seconds [s] whatever listens there.

    Raises
    ------
    InputError
        One line naming ``--scheduler``: dask.distributed is missing, the address is
        malformed, nothing answers within ``timeout`` (a listener that accepts and never
        replies included), or what answers is no Dask scheduler.
    """
    address = _normalise_address(address)
    if client_class is None:
        try:
            from distributed import Client as client_class
        except ImportError:
            raise InputError("--scheduler: needs dask.distributed; install it with "
                             "pip install 'nylonflex[dask]'") from None
    try:
        return _connect(client_class, address, timeout)
    except (OSError, TimeoutError) as exc:
        raise InputError(f"--scheduler: no Dask scheduler answers at {address} "
                         f"within {timeout:g} s ({type(exc).__name__}); start one with "
                         "'dask scheduler' (its default port is 8786; 8787 is the "
                         "dashboard)") from None
    except Exception as exc:  # noqa: BLE001 - garbage from whatever listens there
        reason = " ".join(str(exc).split())[:100] or type(exc).__name__
        raise InputError(f"--scheduler: what answers at {address} is not a Dask "
                         f"scheduler ({type(exc).__name__}: {reason}); give the "
                         "address of 'dask scheduler' (its default port is 8786)"
                         ) from None


def _disarm(exc, client_class):
    """Close the half-made client a failed connection left in ``exc``'s traceback (a
    listener that answered garbage), so that its finaliser does not wait 10 s at exit and
    print "Exception ignored ... TimeoutError" after the one line of the error."""
    tb = exc.__traceback__
    while tb is not None:
        obj = tb.tb_frame.f_locals.get("self")
        if isinstance(obj, client_class):
            with contextlib.suppress(Exception):
                obj.close(timeout=1)
            with contextlib.suppress(Exception):
                obj._Client__loop = None  # what its __del__ checks before closing again
            return
        tb = tb.tb_next
