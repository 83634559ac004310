"""What the security tests share: the web console tests' daemon and browser helpers (tests/web/console_fixture.py,
reused, not copied), a self-signed certificate made by openssl(1), and the distinctive strings the tests hunt for."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "web"))

from console_fixture import (ARTIFACTS, BIN_DIR, ConsoleLog, Daemon, browser, create_key,  # noqa: E402,F401
                             free_port, screenshot, simulator, wait_for)


def self_signed_certificate(directory: Path, san: str) -> tuple[Path, Path]:
    """A P-256 certificate for `san` that is its own CA, as tests/integration/access_test.cpp makes one. 90 days:
    testssl.sh calls a certificate expiring within 30 days a weakness, and one valid beyond 398 days too."""
    cert, key = directory / "cert.pem", directory / "key.pem"
    subprocess.run(["/usr/bin/openssl", "req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:P-256",
                    "-nodes", "-keyout", str(key), "-out", str(cert), "-days", "90", "-subj", "/CN=colorlab test",
                    "-addext", f"subjectAltName={san}"], check=True, capture_output=True, timeout=60)
    return cert, key
