#!/usr/bin/env python3
"""A TCP proxy on 127.0.0.1 in front of the S3 store that misbehaves on a plan, for colorlab-ship's fault tests
(tests/fleet/ship_faults_test.cpp). colorlab-ship opens one connection per request, so connections are requests.

    ship_faults_proxy.py UPSTREAM_PORT PLAN

PLAN is a comma-separated list of ACTION:COUNT taken in order, then `pass` for ever:
  pass:N   relay N requests to the store unchanged
  503:N    answer N requests `503 Service Unavailable` with an S3 <Code>SlowDown</Code> body
  stall:N  read N requests and never answer (the connection stays open until the client gives up)
The port it listens on is printed as the first line of stdout; then one line per request, `N ACTION`.
"""
import socket
import sys
import threading

BODY_503 = (b'<?xml version="1.0" encoding="UTF-8"?><Error><Code>SlowDown</Code>'
            b'<Message>Please reduce your request rate.</Message></Error>')


def relay(src, dst):
    try:
        while True:
            data = src.recv(65536)
            if not data:
                break
            dst.sendall(data)
    except OSError:
        pass
    finally:
        for s in (src, dst):
            try:
                s.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass


def read_head(conn):
    data = b""
    while b"\r\n\r\n" not in data:
        chunk = conn.recv(65536)
        if not chunk:
            break
        data += chunk
    return data


def serve(conn, action, upstream_port):
    if action == "pass":
        up = socket.create_connection(("127.0.0.1", upstream_port))
        threading.Thread(target=relay, args=(conn, up), daemon=True).start()
        relay(up, conn)
        return
    read_head(conn)
    if action == "503":
        conn.sendall(b"HTTP/1.1 503 Service Unavailable\r\nContent-Type: application/xml\r\n"
                     b"Content-Length: " + str(len(BODY_503)).encode() + b"\r\nConnection: close\r\n\r\n" + BODY_503)
        conn.close()
        return
    # stall: hold the connection, reading whatever comes, until the client closes it.
    try:
        while conn.recv(65536):
            pass
    except OSError:
        pass
    conn.close()


def main():
    upstream_port = int(sys.argv[1])
    plan = []
    for part in sys.argv[2].split(","):
        action, count = part.split(":")
        if action not in ("pass", "503", "stall"):
            raise SystemExit(f"unknown action {action!r}")
        plan += [action] * int(count)
    listener = socket.socket()
    listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    listener.bind(("127.0.0.1", 0))
    listener.listen(64)
    print(listener.getsockname()[1], flush=True)
    n = 0
    while True:
        conn, _ = listener.accept()
        action = plan[n] if n < len(plan) else "pass"
        n += 1
        print(n, action, flush=True)
        threading.Thread(target=serve, args=(conn, action, upstream_port), daemon=True).start()


if __name__ == "__main__":
    main()
