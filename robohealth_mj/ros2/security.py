"""SROS2 for the live participant: the keystore and enclave read as ROS 2 reads them, turned into
the DDS Security properties Cyclone DDS takes (the ones rmw_cyclonedds sets).

ROS 2's rules (rcl ``security.c``, rmw_dds_common), followed here:
- security is on when ``ROS_SECURITY_ENABLE`` is exactly ``true``;
- ``ROS_SECURITY_STRATEGY=Enforce`` refuses to run without it; anything else is ``Permissive``:
  what is missing is reported and the participant joins unsecured;
- the enclave's folder is ``<ROS_SECURITY_KEYSTORE>/enclaves/<enclave>``, the enclave the node's
  own (here ``ros2.security.enclave``) unless ``ROS_SECURITY_ENCLAVE_OVERRIDE`` names another;
- that folder holds the six files of :data:`ENCLAVE_FILES`.

A ``ros2.security.*`` value that is set wins over the environment (as a command-line argument
does), except the enclave override, which wins in ROS 2 too.

The PyPI wheel of Cyclone's binding is built without DDS Security; a binding built against a
Cyclone that has it (Debian's ``cyclonedds-dev``: ``make setup-sros2``) carries the plugins.
Which one is installed is read from the binding's library itself.
"""

from __future__ import annotations

import ctypes
import os
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

from robohealth_mj.common.errors import InputError
from robohealth_mj.ros2.keystore import ENCLAVE_FILES, ENCLAVES, document_domains

STRATEGIES = ("Enforce", "Permissive")
PLUGINS = {
    "auth": "dds_security_auth",
    "crypto": "dds_security_crypto",
    "access": "dds_security_ac",
}
PLUGIN_ENTRY = {"auth": "authentication", "crypto": "crypto", "access": "access_control"}
_SECURITY_SYMBOL = "DDS_Security_BinaryPropertySeq_alloc"  # only in a libddsc built with security
HOW_TO_INSTALL = "make setup-sros2 (docs/ros2_live.md, 'A secured graph')"


@dataclass(frozen=True)
class Security:
    """A participant's resolved security: its enclave's folder and the plugins' folder."""

    keystore: Path
    enclave: str
    plugins: Path

    @property
    def folder(self) -> Path:
        return self.keystore / ENCLAVES / self.enclave.strip("/")

    def properties(self) -> dict[str, str]:
        """The participant QoS properties of DDS Security (as rmw_cyclonedds sets them), with
        each plugin by its full path: Debian keeps them out of the loader's path."""
        files = {name: f"file:{self.folder / name}" for name in ENCLAVE_FILES}
        props = {
            "dds.sec.auth.identity_ca": files["identity_ca.cert.pem"],
            "dds.sec.auth.identity_certificate": files["cert.pem"],
            "dds.sec.auth.private_key": files["key.pem"],
            "dds.sec.access.permissions_ca": files["permissions_ca.cert.pem"],
            "dds.sec.access.governance": files["governance.p7s"],
            "dds.sec.access.permissions": files["permissions.p7s"],
        }
        for kind, library in PLUGINS.items():
            props[f"dds.sec.{kind}.library.path"] = str(self.plugins / f"lib{library}.so")
            props[f"dds.sec.{kind}.library.init"] = f"init_{PLUGIN_ENTRY[kind]}"
            props[f"dds.sec.{kind}.library.finalize"] = f"finalize_{PLUGIN_ENTRY[kind]}"
        if (self.folder / "crl.pem").is_file():  # optional, as rmw_dds_common reads it
            props["org.eclipse.cyclonedds.sec.auth.crl"] = f"file:{self.folder / 'crl.pem'}"
        return props


@cache
def binding_library() -> Path:
    """The Cyclone DDS library the installed Python binding loads."""
    from cyclonedds.__library__ import library_path

    return Path(library_path)


def binding_name() -> str:
    from importlib.metadata import version

    return f"cyclonedds {version('cyclonedds')} ({binding_library().resolve()})"


@cache
def binding_has_security() -> bool:
    """Whether the binding's Cyclone was built with DDS Security (the PyPI wheel's is not)."""
    try:
        return hasattr(ctypes.CDLL(str(binding_library())), _SECURITY_SYMBOL)
    except OSError:
        return False


def plugin_folder(configured: str | None = None) -> Path | None:
    """Where the three security plugins are: ``configured``, else beside the binding's library
    or in Debian's private folder of it (``libddsc0debian``)."""
    library = binding_library()
    candidates = [Path(configured)] if configured else []
    for base in dict.fromkeys((library.parent, library.resolve().parent)):
        candidates += [base, base / "libddsc0debian"]
    for folder in candidates:
        if all((folder / f"lib{name}.so").is_file() for name in PLUGINS.values()):
            return folder
    return None


def _setting(cfg: Mapping[str, Any] | None, key: str) -> Any:
    return None if cfg is None else cfg.get(key)


def resolve_security(
    cfg: Mapping[str, Any] | None, domain_id: int, environ: Mapping[str, str] = os.environ
) -> Security | None:
    """The participant's security from ``ros2.security`` and the environment, as ROS 2 reads
    it; None when off. Enforce: what is missing is one line (``InputError``). Permissive: it is
    one line on stderr and the participant joins unsecured (None)."""
    enable = _setting(cfg, "enable")
    if enable is None:
        enable = environ.get("ROS_SECURITY_ENABLE") == "true"
    elif not isinstance(enable, bool):
        raise InputError(f"ros2.security.enable must be true, false or null, got {enable!r}")
    if not enable:
        return None
    strategy = _setting(cfg, "strategy")
    if strategy is not None and strategy not in STRATEGIES:
        raise InputError(
            f"ros2.security.strategy must be one of {list(STRATEGIES)}, got {strategy!r}"
        )
    enforce = (strategy or environ.get("ROS_SECURITY_STRATEGY")) == "Enforce"
    keystore = _setting(cfg, "keystore") or environ.get("ROS_SECURITY_KEYSTORE")
    enclave = environ.get("ROS_SECURITY_ENCLAVE_OVERRIDE") or _setting(cfg, "enclave") or "/"
    problem = _problem(keystore, enclave, domain_id)
    plugins = None
    if problem is None:
        if not binding_has_security():
            problem = f"this binding has no DDS Security: {binding_name()}; {HOW_TO_INSTALL}"
        elif (plugins := plugin_folder(_setting(cfg, "plugins"))) is None:
            problem = (
                f"no DDS Security plugins (lib{PLUGINS['auth']}.so …) beside "
                f"{binding_library()} (ros2.security.plugins names their folder)"
            )
    if problem is None:
        return Security(Path(keystore), enclave, plugins)
    if enforce:
        raise InputError(f"ros2.security (Enforce): {problem}")
    print(f"ros2.security (Permissive): {problem}; joining unsecured", file=sys.stderr, flush=True)
    return None


def _problem(keystore: str | None, enclave: str, domain_id: int) -> str | None:
    """What keeps the enclave from being used, in words; None when it can be."""
    if not keystore:
        return "no keystore (ROS_SECURITY_KEYSTORE or ros2.security.keystore)"
    folder = Path(keystore) / ENCLAVES / enclave.strip("/")
    if not Path(keystore).is_dir():
        return f"keystore {keystore}: no such folder"
    if not folder.is_dir():
        return f"keystore {keystore}: no enclave {enclave} ({folder} is missing)"
    for name, what in ENCLAVE_FILES.items():
        if not (folder / name).is_file():
            return f"enclave {enclave}: no {name} ({what}) in {folder}"
    for name in ("governance.p7s", "permissions.p7s"):
        domains = document_domains(folder / name)
        if not any(low <= domain_id <= high for low, high in domains):
            named = ", ".join(str(a) if a == b else f"{a}-{b}" for a, b in domains) or "none"
            return (f"enclave {enclave}: its {name} names domain {named}, not domain "
                    f"{domain_id} (ros2.domain_id / ROS_DOMAIN_ID)")  # fmt: skip
    return None
