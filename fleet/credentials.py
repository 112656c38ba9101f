"""A fleet's credentials: its own certificate authority and one certificate per identity, for Zenoh's mutual TLS.

An identity is what one Zenoh session presents: a drone (``d1@search``), a process speaking for several drones
(``w1@search``), an operator (``operator@search``) or the router (``router@search``, with the addresses it is
reached at). The certificate's common name is the identity; the router's access-control rules give each name its
rights. Keys are ECDSA P-256, made with the ``cryptography`` package; every file is written readable by its owner
only (0600, in a 0700 folder). :class:`Authority` makes them; :meth:`Identity.read` reads and checks them before a
session opens (signed by the fleet's CA, in date, the key that belongs to the certificate, the fleet's name).
"""

from __future__ import annotations

import datetime
import ipaddress
import os
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from aeroexec.extras import require
from aeroexec.limits import InputError, read_bytes

with require("fleet"):
    from cryptography import x509
    from cryptography.exceptions import InvalidSignature, UnsupportedAlgorithm
    from cryptography.hazmat.primitives import hashes, serialization
    from cryptography.hazmat.primitives.asymmetric import ec
    from cryptography.hazmat.primitives.serialization import load_pem_private_key
    from cryptography.utils import CryptographyDeprecationWarning
    from cryptography.x509.oid import ExtendedKeyUsageOID, NameOID

CA_CERTIFICATE = "ca.pem"
CA_KEY = "ca.key"
ROUTER = "router"
OPERATOR = "operator"
LOCAL_HOSTS = ("127.0.0.1", "localhost")
MAX_PEM = 64 * 1024  # bytes: a certificate or key file
CA_DAYS = 3650
IDENTITY_DAYS = 365
RENEW_DAYS = 30  # an identity expiring sooner is made again


class CredentialsError(ValueError):
    """Credentials that cannot be made or used; the text names the file and why."""


def common_name(name: str, fleet: str) -> str:
    """The certificate's common name of identity ``name`` in ``fleet``: ``name@fleet``."""
    return f"{name}@{fleet}"


@dataclass(frozen=True)
class Material:
    """An identity's files read and checked: PEM bytes for Zenoh, and the common name its certificate holds."""

    name: str
    ca: bytes
    certificate: bytes
    key: bytes


@dataclass(frozen=True)
class Identity:
    """Where an identity's certificate and key are, and the fleet CA's certificate that vouches for the others."""

    certificate: Path
    key: Path
    ca: Path

    @classmethod
    def at(cls, path: str | Path, name: str) -> Identity:
        """The identity ``name`` in the folder ``path`` (``name.pem``, ``name.key``, ``ca.pem``), or the certificate
        file ``path`` itself (its key beside it with the suffix ``.key``, the CA's ``ca.pem`` in the same folder)."""
        path = Path(path)
        if path.is_dir() or path.suffix != ".pem":
            return cls(path / f"{name}.pem", path / f"{name}.key", path / CA_CERTIFICATE)
        return cls(path, path.with_suffix(".key"), path.parent / CA_CERTIFICATE)

    def read(self, fleet: str) -> Material:
        """The files, checked: :class:`CredentialsError` naming the file when one is missing, unreadable, not
        made by the fleet's CA, out of date, of another fleet, or the key is not the certificate's."""
        ca_pem, cert_pem, key_pem = (_read(p, what) for p, what in ((self.ca, "the fleet's CA certificate"),
                                                                      (self.certificate, "the certificate"),
                                                                      (self.key, "the key")))
        ca, certificate = _certificate(ca_pem, self.ca), _certificate(cert_pem, self.certificate)
        try:
            key = load_pem_private_key(key_pem, password=None)
        except (ValueError, TypeError, UnsupportedAlgorithm) as error:
            raise CredentialsError(f"{self.key}: not a private key without a passphrase (PEM): {error}") from None
        try:
            certificate.verify_directly_issued_by(ca)
        except (ValueError, TypeError, InvalidSignature, UnsupportedAlgorithm):
            raise CredentialsError(f"{self.certificate}: not made by the fleet's CA ({self.ca})") from None
        if _public(key) != _public(certificate):
            raise CredentialsError(f"{self.key}: not the key of {self.certificate}")
        now = datetime.datetime.now(datetime.UTC)
        if not certificate.not_valid_before_utc <= now <= certificate.not_valid_after_utc:
            raise CredentialsError(f"{self.certificate}: valid from {certificate.not_valid_before_utc:%Y-%m-%d} to "
                                   f"{certificate.not_valid_after_utc:%Y-%m-%d}, not now: make it again")
        if _is_ca(certificate):
            raise CredentialsError(f"{self.certificate}: a CA's certificate is no member's identity")
        name = _name(certificate)
        if not name.endswith(f"@{fleet}"):
            raise CredentialsError(f"{self.certificate}: the identity {name!r} is not of fleet {fleet}")
        return Material(name, ca_pem, cert_pem, key_pem)

    def common_name(self) -> str:
        """The identity its certificate names (read without the other checks)."""
        return _name(_certificate(_read(self.certificate, "the certificate"), self.certificate))


class Authority:
    """The fleet's certificate authority in ``folder``: loaded when ``ca.pem`` and ``ca.key`` are there, else made."""

    def __init__(self, folder: str | Path, fleet: str) -> None:
        self.folder, self.fleet = Path(folder), fleet
        certificate, key = self.folder / CA_CERTIFICATE, self.folder / CA_KEY
        if certificate.exists() or key.exists():
            self.certificate = _certificate(_read(certificate, "the fleet's CA certificate"), certificate)
            try:
                self.key = load_pem_private_key(_read(key, "the fleet's CA key"), password=None)
            except (ValueError, TypeError, UnsupportedAlgorithm) as error:
                raise CredentialsError(f"{key}: not a private key without a passphrase (PEM): {error}") from None
            if _public(self.key) != _public(self.certificate):
                raise CredentialsError(f"{key}: not the key of {certificate}")
            return
        _private_folder(self.folder)
        self.key = _new_key()
        subject = x509.Name([x509.NameAttribute(x509.oid.NameOID.COMMON_NAME, f"aeroexec fleet {fleet} CA")])
        self.certificate = _builder(subject, subject, self.key, CA_DAYS).add_extension(
            x509.BasicConstraints(ca=True, path_length=0), critical=True).add_extension(
            x509.KeyUsage(digital_signature=True, key_cert_sign=True, crl_sign=True, content_commitment=False,
                          key_encipherment=False, data_encipherment=False, key_agreement=False,
                          encipher_only=False, decipher_only=False), critical=True).sign(self.key, hashes.SHA256())
        _write(key, _key_pem(self.key))
        _write(certificate, _certificate_pem(self.certificate))

    def issue(self, name: str, certificate: Path | None = None, key: Path | None = None,
              hosts: tuple[str, ...] = ()) -> Identity:
        """Identity ``name`` (``name.pem``/``name.key`` in the folder unless given, with a copy of ``ca.pem`` beside
        it), made unless a valid one is there (signed by this CA, the same name, ``hosts`` among its addresses, not
        expiring within 30 days)."""
        certificate = certificate or self.folder / f"{name}.pem"
        key = key or certificate.with_suffix(".key")
        identity = Identity(certificate, key, self.folder / CA_CERTIFICATE)
        if not self._still_good(identity, name, hosts):
            self._make(identity, name, hosts)
        beside = certificate.parent / CA_CERTIFICATE  # a folder of certificates holds the CA's that checks them
        ca = _certificate_pem(self.certificate)
        if beside != identity.ca and (not beside.exists() or _read(beside, "the fleet's CA certificate") != ca):
            _write(beside, ca)
        return identity

    def _make(self, identity: Identity, name: str, hosts: tuple[str, ...]) -> None:
        private = _new_key()
        subject = x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, common_name(name, self.fleet))])
        builder = _builder(subject, self.certificate.subject, private, IDENTITY_DAYS).add_extension(
            x509.BasicConstraints(ca=False, path_length=None), critical=True).add_extension(
            x509.ExtendedKeyUsage([ExtendedKeyUsageOID.SERVER_AUTH, ExtendedKeyUsageOID.CLIENT_AUTH]),
            critical=False)
        if hosts:
            builder = builder.add_extension(x509.SubjectAlternativeName([_address(h) for h in hosts]), critical=False)
        for path in {identity.certificate.parent, identity.key.parent}:
            _private_folder(path)
        _write(identity.key, _key_pem(private))
        _write(identity.certificate, _certificate_pem(builder.sign(self.key, hashes.SHA256())))

    def _still_good(self, identity: Identity, name: str, hosts: tuple[str, ...]) -> bool:
        if not identity.certificate.exists() or not identity.key.exists():
            return False
        try:
            identity.read(self.fleet)
            certificate = _certificate(_read(identity.certificate, "the certificate"), identity.certificate)
        except CredentialsError:
            return False
        if _name(certificate) != common_name(name, self.fleet):
            return False
        if certificate.not_valid_after_utc - datetime.datetime.now(datetime.UTC) < datetime.timedelta(RENEW_DAYS):
            return False
        try:
            known = {str(a.value) for a in certificate.extensions.get_extension_for_class(
                x509.SubjectAlternativeName).value}
        except x509.ExtensionNotFound:
            known = set()
        return {str(_address(h).value) for h in hosts} <= known


# -- helpers ---------------------------------------------------------------------------------------------------------
def _read(path: Path, what: str) -> bytes:
    try:
        return read_bytes(path, MAX_PEM, what)
    except InputError as error:
        raise CredentialsError(str(error)) from None


def _certificate(data: bytes, path: Path) -> x509.Certificate:
    try:
        with warnings.catch_warnings():  # a certificate RFC 5280 disallows (a negative serial) is refused below
            warnings.simplefilter("ignore", CryptographyDeprecationWarning)
            certificate = x509.load_pem_x509_certificate(data)
        certificate.public_key()  # a key of a kind this machine can check
    except (ValueError, x509.InvalidVersion, UnsupportedAlgorithm) as error:
        raise CredentialsError(f"{path}: not a certificate (PEM) this machine can check: {error}") from None
    return certificate


def _is_ca(certificate: x509.Certificate) -> bool:
    try:
        return certificate.extensions.get_extension_for_class(x509.BasicConstraints).value.ca
    except x509.ExtensionNotFound:
        return False


def _name(certificate: x509.Certificate) -> str:
    names = certificate.subject.get_attributes_for_oid(NameOID.COMMON_NAME)
    return str(names[0].value) if names else ""


def _public(key: Any) -> bytes:  # a private key or a certificate
    public = key.public_key()
    return public.public_bytes(serialization.Encoding.DER, serialization.PublicFormat.SubjectPublicKeyInfo)


def _new_key() -> ec.EllipticCurvePrivateKey:
    return ec.generate_private_key(ec.SECP256R1())


def _builder(subject: x509.Name, issuer: x509.Name, key: Any, days: int) -> x509.CertificateBuilder:
    now = datetime.datetime.now(datetime.UTC)
    return (x509.CertificateBuilder().subject_name(subject).issuer_name(issuer).public_key(key.public_key())
            .serial_number(x509.random_serial_number()).not_valid_before(now - datetime.timedelta(hours=1))
            .not_valid_after(now + datetime.timedelta(days=days)))


def _address(host: str) -> x509.GeneralName:
    try:
        return x509.IPAddress(ipaddress.ip_address(host))
    except ValueError:
        return x509.DNSName(host)


def _key_pem(key: Any) -> bytes:
    return key.private_bytes(serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8,
                             serialization.NoEncryption())


def _certificate_pem(certificate: x509.Certificate) -> bytes:
    return certificate.public_bytes(serialization.Encoding.PEM)


def _private_folder(folder: Path) -> None:
    try:
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
    except OSError as error:
        raise CredentialsError(f"{folder}: cannot make the credentials folder: {error.strerror or error}") from None


def _write(path: Path, data: bytes) -> None:
    """``data`` to ``path``, readable and writable by its owner only (also when the file was there before)."""
    try:
        descriptor = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        with os.fdopen(descriptor, "wb") as file:
            os.fchmod(file.fileno(), 0o600)
            file.write(data)
    except OSError as error:
        raise CredentialsError(f"{path}: cannot be written: {error.strerror or error}") from None
