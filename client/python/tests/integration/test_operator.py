"""An operator request seen in follow() and answered from Python: a lab's own campaign (dropped into
<state>/campaigns, as a lab adds one) asks for something the simulated lab's hands cannot do."""
import unittest

from daemon_fixture import Daemon, skip_unless_served

ASK = '''
return {
  description = "asks the operator one question (the Python client's test)",
  needs = {},
  parameters = {},
  run = function(p)
    lab.progress(0.0, "asking")
    local a = lab.operator.request { action = "confirm_filter", prompt = "Is the ND filter off the lens?",
                                     options = { "off", "on" }, default = "on", timeout_s = 3600 }
    lab.progress(1.0, "answered")
    return { answer = a.answer, by = a.by }
  end,
}
'''


class OperatorRequestTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.daemon = Daemon()
        cls.addClassCleanup(cls.daemon.cleanup)
        campaigns = cls.daemon.state / "campaigns"
        campaigns.mkdir(exist_ok=True)
        (campaigns / "python-ask.lua").write_text(ASK)

    def test_a_request_is_followed_listed_and_answered(self):
        lab = self.daemon.client
        self.assertIn("python-ask", lab.campaigns()["name"].tolist())
        skip_unless_served(self, lambda: next(iter(lab.events(reconnect=False))), "GET /v1/events/stream")
        e = lab.start("python-ask")
        answered = False
        seen = []
        gen = lab.follow(e)
        try:
            while True:
                p = next(gen)
                seen.append(p)
                if p.kind == "operator" and p.request.get("event") == "posted" and not answered:
                    self.assertEqual(p.request["action"], "confirm_filter")
                    [listed] = [r for r in lab.requests() if r["id"] == p.request["id"]]
                    self.assertEqual(listed["options"], ["off", "on"])
                    self.assertEqual(listed["execution_id"], e.id)
                    lab.answer(listed, "off", by="python-test")
                    answered = True
        except StopIteration as stop:
            final = stop.value
        self.assertTrue(answered, [str(p) for p in seen])
        self.assertEqual(final.status, "finished_ok")
        events = [p.request["event"] for p in seen if p.kind == "operator"]
        self.assertEqual(events, ["posted", "answered"])
        self.assertEqual(lab.requests(), [])
        result = lab.run(final.run_id)["summary"]["script"]
        self.assertEqual((result["answer"], result["by"]), ("off", "python-test"))


if __name__ == "__main__":
    unittest.main()
