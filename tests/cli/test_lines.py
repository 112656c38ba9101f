"""The run's stdout writes whole lines only: a mission printing from its thread never splits an event line."""

import io
import threading

from aeroexec.cli.lines import LineWriter


def test_lines_written_piecewise_by_many_threads_never_interleave():
    target = io.StringIO()
    out = LineWriter(target)
    start = threading.Barrier(8)

    def writer(mark: str) -> None:
        start.wait()
        for _ in range(200):
            for _ in range(5):  # one line in five pieces, as print(a, b, c) writes them
                out.write(mark * 7)
            out.write("\n")

    threads = [threading.Thread(target=writer, args=(chr(ord("a") + i),)) for i in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    lines = target.getvalue().splitlines()
    assert len(lines) == 8 * 200
    assert all(len(line) == 35 and len(set(line)) == 1 for line in lines)


def test_an_unterminated_line_is_written_out_at_the_end():
    target = io.StringIO()
    out = LineWriter(target)
    print("first", file=out)
    out.write("no newline yet")
    out.flush()
    assert target.getvalue() == "first\n"
    out.finish()
    assert target.getvalue() == "first\nno newline yet\n"
