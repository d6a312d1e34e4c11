"""Run the command line in this process (shared by the test files that check its output)."""
import contextlib
import io


def run_in_process(argv):
    """cli.main in this process: (exit code, stdout, stderr); argparse's SystemExit caught."""
    from infsup_contact import cli

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = cli.main(argv)
        except SystemExit as exc:
            code = exc.code
    return code, out.getvalue(), err.getvalue()
