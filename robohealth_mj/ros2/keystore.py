"""An SROS2 keystore without ROS: a CA, the default governance, and enclaves with their grants.

The layout is the one ``ros2 security create_keystore`` and ``create_enclave`` write (ros2/sros2),
so a keystore made here works with ROS 2 nodes and one made by ``ros2 security`` works here::

    <keystore>/public/ca.cert.pem           identity_ca.cert.pem, permissions_ca.cert.pem -> it
    <keystore>/private/ca.key.pem           identity_ca.key.pem, permissions_ca.key.pem -> it
    <keystore>/enclaves/governance.xml      and governance.p7s, signed by the permissions CA
    <keystore>/enclaves/<enclave>/          cert.pem, key.pem (CN = the enclave's name),
                                            permissions.xml and .p7s, and links to the CA
                                            certificates and the governance

Keys are NIST P-256 (DDS Security 9.3.1 asks for prime256v1) signed with SHA-256; the governance
and permissions are S/MIME-signed as OpenSSL's ``smime -sign -text`` writes them, which is what
the DDS Security plugins verify. Every file is owner-only (keys and certificates alike: the
keystore is one site's secret), every folder 0700.
"""

from __future__ import annotations

import datetime
import os
import re
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from xml.sax.saxutils import escape

from robohealth_mj.common.atomic import atomic_write_bytes
from robohealth_mj.common.errors import InputError

PUBLIC, PRIVATE, ENCLAVES = "public", "private", "enclaves"
CA_NAME = "sros2CA"  # the CA's common name, as sros2 names it
VALID_DAYS = 3650  # sros2's validity; a site rotates by making a new keystore
# ROS 2 graph information that rmw_cyclonedds and rmw_fastrtps exchange: sros2 grants it to
# every enclave, so a ROS node's permissions and ours read alike
ROS_DISCOVERY_TOPIC = "ros_discovery_info"
# The files one enclave needs, as rmw_dds_common looks for them (name -> what it is)
ENCLAVE_FILES = {
    "identity_ca.cert.pem": "identity CA certificate",
    "cert.pem": "enclave certificate",
    "key.pem": "enclave private key",
    "permissions_ca.cert.pem": "permissions CA certificate",
    "governance.p7s": "signed governance",
    "permissions.p7s": "signed permissions",
}
_ENCLAVE_NAME = re.compile(r"^/([A-Za-z_][A-Za-z0-9_]*(/[A-Za-z_][A-Za-z0-9_]*)*)?$")


@dataclass(frozen=True)
class Grant:
    """What an enclave may publish and subscribe to: ROS topic names (``/a/b``), where ``*``
    matches any characters (``/arm1/*``); everything else is denied."""

    publish: tuple[str, ...] = ()
    subscribe: tuple[str, ...] = ()
    ros_discovery: bool = True  # the ROS 2 graph topic, as sros2 grants it

    @classmethod
    def everything(cls) -> Grant:
        """sros2's default for a new enclave: every topic both ways."""
        return cls(publish=("/*",), subscribe=("/*",))


@dataclass
class Keystore:
    """An SROS2 keystore at ``root`` (made by :func:`create_keystore` or ``ros2 security``)."""

    root: Path
    domain_id: int = 0
    made: list[Path] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.root = Path(self.root)

    def enclave_dir(self, enclave: str) -> Path:
        return self.root / ENCLAVES / enclave.strip("/")

    def is_valid(self) -> bool:
        """The files sros2 requires of a keystore."""
        need = [f"{PUBLIC}/permissions_ca.cert.pem", f"{PUBLIC}/identity_ca.cert.pem",
                f"{PRIVATE}/permissions_ca.key.pem", f"{PRIVATE}/identity_ca.key.pem",
                f"{ENCLAVES}/governance.p7s"]  # fmt: skip
        return all((self.root / name).is_file() for name in need)

    def enclaves(self) -> list[str]:
        """The enclaves that hold a key, by name."""
        base = self.root / ENCLAVES
        return sorted("/" + str(k.parent.relative_to(base)) for k in base.glob("**/key.pem"))


def _crypto():
    from cryptography import x509
    from cryptography.hazmat.primitives import hashes, serialization
    from cryptography.hazmat.primitives.asymmetric import ec
    from cryptography.hazmat.primitives.serialization import pkcs7

    return x509, hashes, serialization, ec, pkcs7


def _secret_dir(path: Path) -> None:
    path.mkdir(parents=True, exist_ok=True, mode=0o700)
    os.chmod(path, 0o700)


def _write(path: Path, payload: bytes, made: list[Path]) -> None:
    atomic_write_bytes(path, payload, mode=0o600)
    made.append(path)


def _link(target: Path, link: Path) -> None:
    """A relative symlink ``link`` -> ``target`` (as sros2 links the CA and the governance)."""
    if link.is_symlink() or link.exists():
        link.unlink()
    link.symlink_to(os.path.relpath(target, link.parent))


def _key_and_cert(name: str, issuer: tuple | None = None, ca: bool = False) -> tuple:
    """A P-256 key and its certificate with common name ``name``, signed by ``issuer``
    (``(certificate, key)``) or by itself."""
    x509, hashes, _, ec, _ = _crypto()
    key = ec.generate_private_key(ec.SECP256R1())
    subject = x509.Name([x509.NameAttribute(x509.oid.NameOID.COMMON_NAME, name)])
    issuer_cert, issuer_key = issuer if issuer else (None, key)
    now = datetime.datetime.now(datetime.UTC).replace(microsecond=0)
    cert = (
        x509.CertificateBuilder()
        .subject_name(subject)
        .issuer_name(issuer_cert.subject if issuer_cert else subject)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        # a day back, as sros2 does, so a peer whose clock lags a little still accepts it
        .not_valid_before(now - datetime.timedelta(days=1))
        .not_valid_after(now + datetime.timedelta(days=VALID_DAYS))
        .add_extension(x509.BasicConstraints(ca=ca, path_length=1 if ca else None), critical=ca)
        .sign(issuer_key, hashes.SHA256())
    )
    return key, cert


def _pem(key=None, cert=None) -> bytes:
    _, _, serialization, _, _ = _crypto()
    if cert is not None:
        return cert.public_bytes(serialization.Encoding.PEM)
    return key.private_bytes(
        serialization.Encoding.PEM,
        serialization.PrivateFormat.PKCS8,
        serialization.NoEncryption(),
    )


def _load_ca(keystore: Keystore, which: str) -> tuple:
    """The ``identity`` or ``permissions`` CA's certificate and key."""
    x509, _, serialization, _, _ = _crypto()
    cert_file = keystore.root / PUBLIC / f"{which}_ca.cert.pem"
    key_file = keystore.root / PRIVATE / f"{which}_ca.key.pem"
    for path in (cert_file, key_file):
        if not path.is_file():
            raise InputError(f"keystore {keystore.root}: no {path.relative_to(keystore.root)}")
    cert = x509.load_pem_x509_certificate(cert_file.read_bytes())
    key = serialization.load_pem_private_key(key_file.read_bytes(), None)
    return cert, key


def sign(document: bytes, signer: tuple) -> bytes:
    """``document`` S/MIME-signed (detached, text) by ``signer`` (certificate, key)."""
    _, hashes, serialization, _, pkcs7 = _crypto()
    cert, key = signer
    builder = (
        pkcs7.PKCS7SignatureBuilder().set_data(document).add_signer(cert, key, hashes.SHA256())
    )
    options = [pkcs7.PKCS7Options.Text, pkcs7.PKCS7Options.DetachedSignature]
    return builder.sign(serialization.Encoding.SMIME, options)


def governance_xml(domain_id: int) -> bytes:
    """sros2's default governance: only authenticated participants join; discovery, liveliness
    and every topic's data encrypted; reads and writes checked against each one's permissions;
    RTPS messages signed."""
    rule = (
        "<topic_rule><topic_expression>*</topic_expression>"
        "<enable_discovery_protection>true</enable_discovery_protection>"
        "<enable_liveliness_protection>true</enable_liveliness_protection>"
        "<enable_read_access_control>true</enable_read_access_control>"
        "<enable_write_access_control>true</enable_write_access_control>"
        "<metadata_protection_kind>ENCRYPT</metadata_protection_kind>"
        "<data_protection_kind>ENCRYPT</data_protection_kind></topic_rule>"
    )
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation='
        '"http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">\n'
        f"<domain_access_rules><domain_rule><domains><id>{int(domain_id)}</id></domains>"
        "<allow_unauthenticated_participants>false</allow_unauthenticated_participants>"
        "<enable_join_access_control>true</enable_join_access_control>"
        "<discovery_protection_kind>ENCRYPT</discovery_protection_kind>"
        "<liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>"
        "<rtps_protection_kind>SIGN</rtps_protection_kind>"
        f"<topic_access_rules>{rule}</topic_access_rules></domain_rule></domain_access_rules>\n"
        "</dds>\n"
    ).encode()


def dds_topic_expression(ros_topic: str) -> str:
    """A ROS topic name (``/a/b``, wildcards kept) as the DDS topic it travels on (``rt/a/b``)."""
    return "rt/" + ros_topic.lstrip("/")


def permissions_xml(enclave: str, grant: Grant, domain_id: int, valid: tuple) -> bytes:
    """The enclave's DDS permissions: ``grant``'s topics allowed on ``domain_id`` for the
    certificate whose subject is ``CN=<enclave>``, within ``valid`` (its certificate's dates),
    everything else denied."""

    def topics(kind: str, names: Iterable[str]) -> str:
        items = "".join(f"<topic>{escape(n)}</topic>" for n in names)
        return f"<{kind}><topics>{items}</topics></{kind}>" if items else ""

    domains = f"<domains><id>{int(domain_id)}</id></domains>"
    allow = (
        f"<allow_rule>{domains}"
        + topics("publish", map(dds_topic_expression, grant.publish))
        + topics("subscribe", map(dds_topic_expression, grant.subscribe))
        + "</allow_rule>"
    )
    if grant.ros_discovery:
        allow += (f"<allow_rule>{domains}{topics('publish', [ROS_DISCOVERY_TOPIC])}"
                  f"{topics('subscribe', [ROS_DISCOVERY_TOPIC])}</allow_rule>")  # fmt: skip
    before, after = (d.strftime("%Y-%m-%dT%H:%M:%S") for d in valid)
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation='
        '"http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">\n'
        f'<permissions><grant name="{escape(enclave)}">'
        f"<subject_name>CN={escape(enclave)}</subject_name>"
        f"<validity><not_before>{before}</not_before><not_after>{after}</not_after></validity>"
        f"{allow}<default>DENY</default></grant></permissions>\n"
        "</dds>\n"
    ).encode()


def create_keystore(root: Path | str, domain_id: int = 0) -> Keystore:
    """A new keystore at ``root``: one CA for identities and permissions (as sros2 makes it)
    and the signed default governance for ``domain_id``. An existing keystore is refused."""
    keystore = Keystore(root, domain_id)
    if keystore.is_valid():
        raise InputError(f"keystore {keystore.root} exists already (its CA is kept; add enclaves)")
    for sub in ("", PUBLIC, PRIVATE, ENCLAVES):
        _secret_dir(keystore.root / sub)
    key, cert = _key_and_cert(CA_NAME, ca=True)
    _write(keystore.root / PRIVATE / "ca.key.pem", _pem(key=key), keystore.made)
    _write(keystore.root / PUBLIC / "ca.cert.pem", _pem(cert=cert), keystore.made)
    for which in ("identity", "permissions"):
        _link(
            keystore.root / PUBLIC / "ca.cert.pem", keystore.root / PUBLIC / f"{which}_ca.cert.pem"
        )
        _link(
            keystore.root / PRIVATE / "ca.key.pem", keystore.root / PRIVATE / f"{which}_ca.key.pem"
        )
    governance = governance_xml(domain_id)
    _write(keystore.root / ENCLAVES / "governance.xml", governance, keystore.made)
    _write(
        keystore.root / ENCLAVES / "governance.p7s", sign(governance, (cert, key)), keystore.made
    )
    return keystore


def document_domains(signed: Path) -> list[tuple[int, int]]:
    """The domain ids (ranges, inclusive) a signed governance or permissions document names:
    the S/MIME body is the XML in clear."""
    text = signed.read_text(errors="replace")
    ranges = [(int(v), int(v)) for v in re.findall(r"<id>\s*(\d+)\s*</id>", text)]
    for block in re.findall(r"<id_range>(.*?)</id_range>", text, flags=re.S):
        low = re.search(r"<min>\s*(\d+)", block)
        high = re.search(r"<max>\s*(\d+)", block)
        ranges.append((int(low.group(1)) if low else 0, int(high.group(1)) if high else 232))
    return ranges


def open_keystore(root: Path | str, domain_id: int = 0) -> Keystore:
    """An existing keystore; one line naming what it lacks where it is not one, or where its
    governance does not rule ``domain_id``."""
    keystore = Keystore(root, domain_id)
    if not keystore.root.is_dir():
        raise InputError(f"keystore {keystore.root}: no such folder")
    if not keystore.is_valid():
        raise InputError(
            f"keystore {keystore.root}: not an SROS2 keystore (needs public/, private/ and "
            "enclaves/governance.p7s: python -m robohealth_mj.keystore keystore=PATH makes one)"
        )
    domains = document_domains(keystore.root / ENCLAVES / "governance.p7s")
    if not any(low <= domain_id <= high for low, high in domains):
        raise InputError(
            f"keystore {keystore.root}: its governance rules domain "
            f"{', '.join(f'{a}-{b}' if a != b else str(a) for a, b in domains)}, not {domain_id} "
            "(ros2.domain_id); a keystore per domain, as sros2 makes them"
        )
    return keystore


def create_enclave(keystore: Keystore, enclave: str, grant: Grant) -> Path:
    """The enclave ``enclave`` (``/a/b``) with a new identity signed by the keystore's CA and
    ``grant`` as its signed permissions; an existing enclave keeps its key and gets the new
    permissions (as ``ros2 security create_permission`` replaces them)."""
    if not _ENCLAVE_NAME.match(enclave):
        raise InputError(f"enclave {enclave!r}: a ROS namespace such as /robohealth/monitor")
    folder = keystore.enclave_dir(enclave)
    base = folder
    while base != keystore.root:
        _secret_dir(base)
        base = base.parent
    identity = _load_ca(keystore, "identity")
    x509, _, _, _, _ = _crypto()
    cert_file, key_file = folder / "cert.pem", folder / "key.pem"
    if cert_file.is_file() and key_file.is_file():
        cert = x509.load_pem_x509_certificate(cert_file.read_bytes())
    else:
        key, cert = _key_and_cert(enclave, issuer=identity)
        _write(key_file, _pem(key=key), keystore.made)
        _write(cert_file, _pem(cert=cert), keystore.made)
    for name in ("identity_ca.cert.pem", "permissions_ca.cert.pem"):
        _link(keystore.root / PUBLIC / name, folder / name)
    _link(keystore.root / ENCLAVES / "governance.p7s", folder / "governance.p7s")
    valid = (cert.not_valid_before_utc, cert.not_valid_after_utc)
    document = permissions_xml(enclave, grant, keystore.domain_id, valid)
    _write(folder / "permissions.xml", document, keystore.made)
    signed = sign(document, _load_ca(keystore, "permissions"))
    _write(folder / "permissions.p7s", signed, keystore.made)
    return folder
