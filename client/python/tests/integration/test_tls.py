"""The client over TLS to a colorlabd with its own certificate: trusted through cacert=, refused without."""
import shutil
import subprocess
import tempfile
import unittest
from pathlib import Path

import colorlab
from daemon_fixture import Daemon, skip_unless_served


def make_certificates(d: Path) -> None:
    """A test CA and a server certificate it signed for 127.0.0.1 (the name the client connects to)."""
    def openssl(*args):
        subprocess.run(["openssl", *args], check=True, capture_output=True, cwd=d, timeout=60)

    openssl("req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", "ca.key", "-out", "ca.pem", "-days", "2",
            "-subj", "/CN=colorlab test CA")
    openssl("req", "-newkey", "rsa:2048", "-nodes", "-keyout", "key.pem", "-out", "server.csr",
            "-subj", "/CN=127.0.0.1")
    (d / "san.ext").write_text("subjectAltName = IP:127.0.0.1, DNS:localhost\n")
    openssl("x509", "-req", "-in", "server.csr", "-CA", "ca.pem", "-CAkey", "ca.key", "-CAcreateserial",
            "-out", "cert.pem", "-days", "2", "-extfile", "san.ext")


class TlsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if shutil.which("openssl") is None:
            raise unittest.SkipTest("the openssl command (Debian package openssl) makes the test certificates")
        cls.certs = Path(tempfile.mkdtemp(prefix="colorlab-python-tls-"))
        cls.addClassCleanup(shutil.rmtree, cls.certs, True)
        make_certificates(cls.certs)
        cls.daemon = Daemon(extra=f'[access]\ntls_certificate = "{cls.certs / "cert.pem"}"\n'
                                  f'tls_private_key = "{cls.certs / "key.pem"}"\n')
        cls.addClassCleanup(cls.daemon.cleanup)
        cls.https = f"https://127.0.0.1:{cls.daemon.endpoint['port']}"

    def test_trusted_through_cacert(self):
        with colorlab.Client(self.https, cacert=self.certs / "ca.pem", key="") as lab:
            self.assertIs(lab.status()["simulated_lab"], True)
            self.assertIn("items", lab.conn.get("/v1/runs"))
            first = skip_unless_served(self, lambda: next(iter(lab.events(reconnect=False))), "GET /v1/events/stream")
            self.assertEqual(first.topic, "snapshot")

    def test_refused_without_the_ca(self):
        with colorlab.Client(self.https, key="") as lab:
            with self.assertRaises(colorlab.ConnectionFailed) as caught:
                lab.status()
            self.assertIn("cacert", str(caught.exception))
            with self.assertRaises(colorlab.ConnectionFailed):
                next(iter(lab.events()))

    def test_plain_http_to_the_tls_listener_fails(self):
        with colorlab.Client(self.https.replace("https:", "http:"), key="", timeout=10) as lab:
            with self.assertRaises(colorlab.ColorlabError):
                lab.status()


if __name__ == "__main__":
    unittest.main()
