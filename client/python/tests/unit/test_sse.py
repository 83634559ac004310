"""The SSE parser against WHATWG HTML §9.2's rules, with the stream cut into chunks everywhere."""
import random
import unittest

from colorlab.sse import SseEvent, SseParser


def parse(chunks, parser=None):
    parser = parser or SseParser()
    out = []
    for c in chunks:
        out.extend(parser.feed(c))
    return out


def every_split(stream: bytes):
    """The stream in two pieces at every position, in three at every pair, and one byte at a time."""
    yield [stream]
    yield [stream[i:i + 1] for i in range(len(stream))]
    for i in range(len(stream) + 1):
        yield [stream[:i], stream[i:]]
    for i in range(len(stream) + 1):
        for j in range(i, len(stream) + 1):
            yield [stream[:i], stream[i:j], stream[j:]]


class ParserTest(unittest.TestCase):
    def test_fields_make_one_event_at_the_blank_line(self):
        evs = parse([b"id: 7\nevent: progress\ndata: {\"a\": 1}\n\n"])
        self.assertEqual(evs, [SseEvent(event="progress", data='{"a": 1}', id="7")])

    def test_data_lines_join_with_newline_and_unnamed_events_are_messages(self):
        evs = parse([b"data: first\ndata: second\ndata\n\n"])
        self.assertEqual(evs, [SseEvent("message", "first\nsecond\n", "")])

    def test_the_specs_example_streams(self):
        # WHATWG: "data\n\ndata\ndata\n\ndata:" → "", "\n", and the unfinished last block is dropped.
        self.assertEqual([e.data for e in parse([b"data\n\ndata\ndata\n\ndata:"])], ["", "\n"])
        # Only the first space after the colon is taken away.
        self.assertEqual([e.data for e in parse([b"data:test\n\ndata: test\n\ndata:  test\n\n"])],
                         ["test", "test", " test"])

    def test_comments_are_skipped_and_counted(self):
        p = SseParser()
        evs = parse([b": keep-alive\n\n:\ndata: x\n: between\n\n"], p)
        self.assertEqual([e.data for e in evs], ["x"])
        self.assertEqual(p.comments, 3)

    def test_a_block_without_data_dispatches_nothing_and_forgets_its_event_name(self):
        evs = parse([b"event: snapshot\nid: 3\n\ndata: y\n\n"])
        self.assertEqual(evs, [SseEvent("message", "y", "3")])

    def test_id_persists_is_reset_by_an_empty_id_and_ignores_nul(self):
        evs = parse([b"id: 1\ndata: a\n\ndata: b\n\nid: 2\x00x\ndata: c\n\nid\ndata: d\n\n"])
        self.assertEqual([(e.data, e.id) for e in evs], [("a", "1"), ("b", "1"), ("c", "1"), ("d", "")])

    def test_retry_takes_ascii_digits_only(self):
        p = SseParser()
        parse([b"retry: 2500\n\n"], p)
        self.assertEqual(p.retry_ms, 2500)
        parse([b"retry: 12a\n\nretry: -5\n\nretry:\n\nretry: \xd9\xa3\n\n"], p)  # Arabic-Indic three
        self.assertEqual(p.retry_ms, 2500)

    def test_unknown_fields_and_field_names_without_colon_are_ignored(self):
        self.assertEqual(parse([b"foo: bar\nevent\ndata: z\n\n"]), [SseEvent("message", "z", "")])

    def test_every_line_ending_and_mixtures(self):
        for sep in (b"\n", b"\r\n", b"\r"):
            stream = sep.join([b"id: 5", b"event: e", b"data: 1", b"data: 2", b"", b"data: 3", b"", b""])
            self.assertEqual(parse([stream]), [SseEvent("e", "1\n2", "5"), SseEvent("message", "3", "5")], sep)
        mixed = b"data: a\r\ndata: b\rdata: c\n\r\n"
        self.assertEqual(parse([mixed]), [SseEvent("message", "a\nb\nc", "")])

    def test_a_crlf_split_between_chunks_is_one_line_end(self):
        # A parser that took the CR as a line end and then the lone LF as a blank line would split this event.
        self.assertEqual(parse([b"data: a\r", b"\ndata: b\r\n\r\n"]), [SseEvent("message", "a\nb", "")])
        # …and a CR then a real blank line (CR CR) stays two line ends.
        self.assertEqual(parse([b"data: a\r", b"\r"]), [SseEvent("message", "a", "")])
        # An empty chunk between the CR and its LF changes nothing.
        self.assertEqual(parse([b"data: a\r", b"", b"\n", b"\n"]), [SseEvent("message", "a", "")])

    def test_every_chunking_gives_the_same_events(self):
        stream = ("\ufeffid: 41\r\nevent: progress\r\ndata: {\"step\": \"patch/A1\", \"λ\": \"380–730 nm\"}\r\n"
                  ": keep-alive\r\n\r\nid: 42\rdata: a\rdata: b\r\rdata: ü\n\n").encode()
        expected = [SseEvent("progress", '{"step": "patch/A1", "λ": "380–730 nm"}', "41"),
                    SseEvent("message", "a\nb", "42"), SseEvent("message", "ü", "42")]
        for chunks in every_split(stream):
            self.assertEqual(parse(chunks), expected, chunks)

    def test_random_chunking_of_a_long_stream(self):
        events = [(str(i), f"topic{i % 3}", f'{{"seq": {i}, "payload": "{"x" * (i % 17)}"}}') for i in range(300)]
        stream = b"".join(f"id: {i}\r\nevent: {t}\r\ndata: {d}\r\n\r\n: ka\n".encode() for i, t, d in events)
        rng = random.Random(10)
        for _ in range(20):
            chunks, pos = [], 0
            while pos < len(stream):
                n = rng.randint(0, 40)
                chunks.append(stream[pos:pos + n])
                pos += n
            got = parse(chunks)
            self.assertEqual([(e.id, e.event, e.data) for e in got], events)

    def test_bom_only_at_the_very_start(self):
        self.assertEqual(parse([b"\xef\xbb", b"\xbfdata: x\n\n"]), [SseEvent("message", "x", "")])
        # Later, a BOM is part of the field name, which makes the line an unknown field.
        self.assertEqual(parse([b"data: x\n\n\xef\xbb\xbfdata: y\n\n"]), [SseEvent("message", "x", "")])

    def test_invalid_utf8_is_replaced_not_fatal(self):
        self.assertEqual(parse([b"data: \xff\n\n"]), [SseEvent("message", "\ufffd", "")])

    def test_an_event_the_stream_ends_in_is_not_dispatched(self):
        self.assertEqual(parse([b"id: 9\ndata: cut"]), [])
        self.assertEqual(parse([b"id: 9\ndata: cut\n"]), [])

    def test_a_parser_resumed_with_a_last_event_id_reports_it_until_a_new_id(self):
        self.assertEqual(parse([b"data: x\n\n"], SseParser("17")), [SseEvent("message", "x", "17")])


if __name__ == "__main__":
    unittest.main()
