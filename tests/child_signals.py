"""For the tests that signal a child process: the child's dispositions set by the test itself.

A non-interactive shell starts a background job (``make test &``) with SIGINT ignored, ``nohup`` ignores
SIGHUP, and a child inherits both; the command line rightly keeps an ignored signal ignored
(``thermofriction._signals.install_signal_handlers``: what nohup asks for), so a test that sends one
must restore its default in the child first: ``subprocess.Popen(..., preexec_fn=default_signals)``."""

import signal

#: the signals the tests send to a child (and the command line handles)
SENT = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def default_signals():
    """In the child, before it runs the command: each signal the tests send back to its default."""
    for s in SENT:
        signal.signal(s, signal.SIG_DFL)
