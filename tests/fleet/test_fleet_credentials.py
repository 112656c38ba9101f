"""A fleet's credentials: made with its own CA, readable by their owner only, checked before a session opens (the
fleet's CA, the key that belongs to the certificate, the fleet's name, the date), and a router's certificate that
must name the address it is reached at."""

import datetime
import stat

import pytest
from aeroexec.cli.main import main
from aeroexec.fleet.access import Roster, access_control
from aeroexec.fleet.credentials import Authority, CredentialsError, Identity
from aeroexec.fleet.fleet_file import load_fleet
from aeroexec.fleet.members import connect, listen
from aeroexec.fleet.transport import TransportError, free_endpoint
from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization


def test_the_fleet_command_makes_every_identity_its_file_names_readable_by_the_owner_only(tmp_path, capsys):
    fleet = tmp_path / "f.yaml"
    fleet.write_text("fleet: search-team\noperators: [alice, bob]\ndrones:\n  - {name: scout-1}\n"
                     "  - {name: d.2, certificate: hosts/w1.pem}\n  - {name: d3, certificate: hosts/w1.pem}\n")
    assert main(["fleet", str(fleet), "--make-credentials", str(tmp_path / "creds"), "--listen",
                 "tls/10.0.0.5:7447"]) == 0
    out = capsys.readouterr().out
    for name in ("router", "scout-1", "w1", "alice", "bob"):
        assert f"{name}: " in out
    made = sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*.*") if p.suffix in (".pem", ".key"))
    assert made == ["creds/alice.key", "creds/alice.pem", "creds/bob.key", "creds/bob.pem", "creds/ca.key",
                    "creds/ca.pem", "creds/router.key", "creds/router.pem", "creds/scout-1.key", "creds/scout-1.pem",
                    "hosts/ca.pem", "hosts/w1.key", "hosts/w1.pem"]
    for path in (*tmp_path.rglob("*.pem"), *tmp_path.rglob("*.key")):
        assert stat.S_IMODE(path.stat().st_mode) == 0o600, path
    assert stat.S_IMODE((tmp_path / "creds").stat().st_mode) == 0o700
    spec = load_fleet(fleet)
    assert spec.identity(spec.drones[1]).read("search-team").name == "w1@search-team"
    assert Identity.at(tmp_path / "creds", "scout-1").read("search-team").name == "scout-1@search-team"
    router = x509.load_pem_x509_certificate((tmp_path / "creds" / "router.pem").read_bytes())
    names = router.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
    assert {str(n.value) for n in names} == {"127.0.0.1", "localhost", "10.0.0.5"}
    before = (tmp_path / "creds" / "scout-1.pem").read_bytes()
    assert main(["fleet", str(fleet), "--make-credentials", str(tmp_path / "creds")]) == 0  # again: kept
    assert (tmp_path / "creds" / "scout-1.pem").read_bytes() == before


def test_an_identity_is_refused_before_any_session_opens_when_it_is_not_the_fleets(tmp_path):
    creds, other = Authority(tmp_path / "creds", "f"), Authority(tmp_path / "other", "f")
    d1, d2, stranger = creds.issue("d1"), creds.issue("d2"), other.issue("d1")
    cases = {
        "not made by the fleet's CA": Identity(stranger.certificate, stranger.key, d1.ca),
        "not the key of": Identity(d1.certificate, d2.key, d1.ca),
        "is not of fleet g": d1,
        "a CA's certificate is no member's identity": Identity(d1.ca, tmp_path / "creds" / "ca.key", d1.ca),
        "cannot read the key": Identity(d1.certificate, tmp_path / "nowhere.key", d1.ca),
        "not a certificate (PEM)": Identity(d1.key, d1.key, d1.ca),
    }
    for message, identity in cases.items():
        with pytest.raises(CredentialsError, match=message.replace("(", r"\(").replace(")", r"\)")):
            identity.read("g" if "fleet g" in message else "f")
    expired = tmp_path / "expired.pem"
    certificate = x509.load_pem_x509_certificate(d1.certificate.read_bytes())
    key = serialization.load_pem_private_key((tmp_path / "creds" / "ca.key").read_bytes(), None)
    old = datetime.datetime(2020, 1, 1, tzinfo=datetime.UTC)
    expired.write_bytes(x509.CertificateBuilder().subject_name(certificate.subject).issuer_name(certificate.issuer)
                        .public_key(certificate.public_key()).serial_number(1).not_valid_before(old)
                        .not_valid_after(old + datetime.timedelta(days=1)).sign(key, hashes.SHA256())
                        .public_bytes(serialization.Encoding.PEM))
    with pytest.raises(CredentialsError, match="valid from 2020-01-01 to 2020-01-02, not now"):
        Identity(expired, d1.key, d1.ca).read("f")


def test_a_router_is_reached_only_at_an_address_its_certificate_names(tmp_path):
    fleet = tmp_path / "f.yaml"
    fleet.write_text("fleet: f\ncredentials: creds\ndrones:\n  - {name: d1, mission: m.py}\n")
    (tmp_path / "m.py").write_text("def mission():\n    pass\n")
    assert main(["fleet", str(fleet), "--make-credentials", str(tmp_path / "creds")]) == 0  # 127.0.0.1, localhost
    spec = load_fleet(fleet)
    port = free_endpoint("tls").rsplit(":", 1)[1]
    router = listen(spec, [f"tls/127.0.0.2:{port}"], tmp_path)
    try:
        with pytest.raises(TransportError, match="as d1@f: is the router running there, with a certificate of this "
                                                 "fleet's CA that names 127.0.0.2"):
            connect(spec, [f"tls/127.0.0.2:{port}"])
    finally:
        router.close()
    with pytest.raises(TransportError, match="tcp/127.0.0.1:1 is not authenticated: a fleet's endpoints are tls/"):
        connect(spec, ["tcp/127.0.0.1:1"])


def test_the_routers_rules_give_each_identity_its_own_drones_keys_and_nothing_else():
    roster = Roster("f", {"d1@f": ("d1",), "w1@f": ("d2", "d3")}, ("operator@f",), routers=("router@f",))
    rules = access_control(roster)
    assert rules["default_permission"] == "deny"
    by_id = {r["id"]: r for r in rules["rules"]}
    policy = {p["subjects"][0]: p["rules"] for p in rules["policies"]}
    subject = {s["id"]: s["cert_common_names"] for s in rules["subjects"]}
    host = next(k for k, names in subject.items() if names == ["w1@f"])
    speak = next(by_id[r] for r in policy[host] if by_id[r]["messages"] == ["put"])
    assert speak["flows"] == ["ingress"] and sorted(speak["key_exprs"]) == sorted(
        f"aeroexec/f/{d}/tick" for d in ("d2", "d3"))
    assert [by_id[r]["key_exprs"] for r in policy["operators"]] == [["aeroexec/f/*/command"]] * 2
    # an operator's query of every drone reaches each member (which may serve only its own drones' keys)
    asked = [by_id[r] for r in policy[host] if by_id[r]["messages"] == ["query"]]
    assert [(r["flows"], r["key_exprs"]) for r in asked] == [(["egress"], ["aeroexec/f/*/command"])]
    serve = next(by_id[r] for r in policy[host] if "declare_queryable" in by_id[r]["messages"])
    assert sorted(serve["key_exprs"]) == ["aeroexec/f/d2/command", "aeroexec/f/d3/command"]
    with pytest.raises(ValueError, match="the drone d2 has two identities"):
        Roster("f", {"a@f": ("d2",), "b@f": ("d2",)})
    with pytest.raises(ValueError, match="both an operator and a drone's"):
        Roster("f", {"a@f": ("d2",)}, ("a@f",))


def test_a_process_identity_speaks_for_exactly_the_drones_it_hosts(tmp_path):
    """A worker hosting d2 and d3 under one identity (w1) may publish as both, not as d1; d1 has its own."""
    import time

    import zenoh
    from aeroexec.fleet.payloads import tick

    fleet = tmp_path / "f.yaml"
    fleet.write_text("fleet: f\ncredentials: creds\ndrones:\n  - {name: d1, mission: m.py}\n"
                     "  - {name: d2, mission: m.py, certificate: creds/w1.pem}\n"
                     "  - {name: d3, mission: m.py, certificate: creds/w1.pem}\n")
    (tmp_path / "m.py").write_text("def mission():\n    pass\n")
    assert main(["fleet", str(fleet), "--make-credentials", str(tmp_path / "creds")]) == 0
    spec = load_fleet(fleet)
    endpoint = free_endpoint("tls")
    router = listen(spec, [endpoint], tmp_path)
    heard = []
    router.session.declare_subscriber("aeroexec/f/**", zenoh.handlers.Callback(
        lambda sample: heard.append(str(sample.key_expr)), indirect=False))
    worker = connect(spec, [endpoint])  # d1 speaks as d1, d2 and d3 as w1: two sessions
    try:
        assert worker.sessions["d2"] is worker.sessions["d3"] is not worker.session
        w1, d1 = worker.sessions["d2"], worker.session
        for session, drone in ((w1, "d2"), (w1, "d3"), (w1, "d1"), (d1, "d1"), (d1, "d2")):
            session.put(f"aeroexec/f/{drone}/tick", tick(drone, [["telemetry", {"position": [0, 0, 0]}]]))
        deadline = time.monotonic() + 5
        while len(heard) < 3 and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(0.3)
    finally:
        worker.close()
        router.close()
    assert sorted(heard) == ["aeroexec/f/d1/tick", "aeroexec/f/d2/tick", "aeroexec/f/d3/tick"]
