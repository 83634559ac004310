"""problem+json answers become the ApiError subclass of their status, carrying the problem's fields;
the API key goes out as a Bearer token."""
import os
import socket
import unittest
from unittest import mock

import colorlab
from colorlab.errors import error_class
from fake_daemon import FakeDaemon


class ErrorMappingTest(unittest.TestCase):
    def test_each_status_maps_to_its_class_with_the_problems_fields(self):
        cases = {400: colorlab.BadRequest, 401: colorlab.Unauthorized, 403: colorlab.Forbidden,
                 404: colorlab.NotFound, 405: colorlab.MethodNotAllowed, 409: colorlab.Conflict,
                 413: colorlab.PayloadTooLarge, 415: colorlab.UnsupportedMediaType,
                 416: colorlab.RangeNotSatisfiable, 422: colorlab.Unprocessable, 500: colorlab.ServerError,
                 502: colorlab.InstrumentError, 503: colorlab.ServiceUnavailable}
        with FakeDaemon() as fake:
            for status in cases:
                fake.routes[("GET", f"/v1/s{status}")] = (
                    lambda h, s=status: h.send_problem(s, f"code-{s}", f"Title {s}", f"detail {s}", f"hint {s}"))
            c = self.enterContext(colorlab.Client(fake.url))
            for status, cls in cases.items():
                with self.assertRaises(cls) as caught:
                    c.conn.get(f"/v1/s{status}")
                e = caught.exception
                self.assertIsInstance(e, colorlab.ApiError)
                self.assertEqual((e.status, e.code, e.title, e.detail, e.hint),
                                 (status, f"code-{status}", f"Title {status}", f"detail {status}", f"hint {status}"))
                self.assertEqual(e.problem["category"], "validation")
                self.assertIn(f"detail {status}", str(e))
                self.assertIn(f"/v1/s{status}", str(e))

    def test_unknown_statuses_fall_back_by_their_hundred(self):
        self.assertIs(error_class(418), colorlab.ApiError)
        self.assertIs(error_class(504), colorlab.ServerError)

    def test_a_body_that_is_not_a_problem_still_raises_with_its_text(self):
        with FakeDaemon() as fake:
            fake.routes[("GET", "/v1/proxy")] = lambda h: h.send_bytes(502, b"<html>bad gateway</html>", "text/html")
            with self.assertRaises(colorlab.InstrumentError) as caught:
                self.enterContext(colorlab.Client(fake.url)).conn.get("/v1/proxy")
            self.assertEqual(caught.exception.status, 502)
            self.assertIn("bad gateway", caught.exception.detail)
            self.assertEqual(caught.exception.code, "")

    def test_no_daemon_is_a_connection_failure(self):
        s = socket.socket()
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
        s.close()  # nothing listens there now
        with self.assertRaises(colorlab.ConnectionFailed) as caught:
            self.enterContext(colorlab.Client(f"http://127.0.0.1:{port}", timeout=5)).status()
        self.assertIn("colorlabd", str(caught.exception))

    def test_a_bad_url_is_refused_at_once(self):
        with self.assertRaises(colorlab.ColorlabError):
            colorlab.Client("127.0.0.1:8765")


class AuthTest(unittest.TestCase):
    def _authorization(self, **client_args):
        with FakeDaemon() as fake:
            fake.routes[("GET", "/v1")] = lambda h: h.send_json(200, {"server": "colorlabd"})
            with colorlab.Client(fake.url, **client_args) as c:
                c.status()
            return fake.requests_to("GET", "/v1")[0][3].get("Authorization")

    def test_the_key_is_a_bearer_token(self):
        with mock.patch.dict(os.environ, {}, clear=False):
            os.environ.pop("COLORLAB_API_KEY", None)
            self.assertEqual(self._authorization(key="clk_abc"), "Bearer clk_abc")
            self.assertIsNone(self._authorization())

    def test_the_key_comes_from_the_environment_unless_given(self):
        with mock.patch.dict(os.environ, {"COLORLAB_API_KEY": "clk_env"}):
            self.assertEqual(self._authorization(), "Bearer clk_env")
            self.assertEqual(self._authorization(key="clk_arg"), "Bearer clk_arg")

    def test_the_key_is_not_in_the_repr(self):
        self.assertNotIn("secret", repr(colorlab.Client("http://127.0.0.1:1", key="secret")))

    def test_401_and_403_are_their_own_classes(self):
        with FakeDaemon() as fake:
            fake.routes[("GET", "/v1/runs")] = lambda h: h.send_problem(401, "unauthorized", "Unauthorized",
                                                                        "this listener needs an API key")
            fake.routes[("POST", "/v1/executions")] = lambda h: h.send_problem(403, "forbidden", "Forbidden",
                                                                               "starting needs the control scope")
            c = self.enterContext(colorlab.Client(fake.url, key="k"))
            with self.assertRaises(colorlab.Unauthorized):
                c.runs()
            with self.assertRaises(colorlab.Forbidden) as caught:
                c.start("luminance-spot", readings=1)
            self.assertEqual(caught.exception.detail, "starting needs the control scope")


if __name__ == "__main__":
    unittest.main()
