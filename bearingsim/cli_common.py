"""What the subcommands share: a study's exit code, whether a progress bar is drawn, the options a
library refusal names, the parser class whose errors are one line. Imported by :mod:`bearingsim.cli` and the command modules beside it (``cli_sweep``,
``cli_sensitivity``, ``cli_wear``, ``cli_animate``), none of which import each other."""
from __future__ import annotations

import argparse
import contextlib
import difflib
import re
import signal
import sys

from bearingsim.errors import UserError
from bearingsim.wording import counted


def _negative_values_joined(args: list[str]) -> list[str]:
    """``args`` with a token that starts as a negative number (``-10%``, ``-0.5``, ``-.5``) after a long option
    joined to it (``--step=-10%``): no bearingsim option starts with a digit, so such a token is a value, and
    argparse takes only the plain numbers it recognises (``-10``) as one. Nothing after ``--`` is changed."""
    out: list[str] = []
    for i, tok in enumerate(args):
        if tok == "--":
            return out + args[i:]
        prev = out[-1] if out else ""
        if prev.startswith("--") and "=" not in prev and re.match(r"-\.?\d", tok):
            out[-1] = f"{prev}={tok}"
        else:
            out.append(tok)
    return out


class Parser(argparse.ArgumentParser):
    """``bearingsim``'s parser and, through argparse's ``parser_class``, every subcommand's: a bad command
    line is one line on stderr, exit 2, ending with the command's ``--help`` (argparse printed a usage block
    of several lines above its error); an unknown choice (a subcommand's name, an option's value) names the
    closest one there is. ``--help`` prints as argparse prints it."""

    def error(self, message: str):
        from bearingsim.outputs import printable

        self.exit(2, f"{self.prog}: error: {printable(message, keep_newlines=False)} ({self.prog} --help)\n")

    def parse_args(self, args=None, namespace=None):
        """argparse's, but an argument no parser took is refused by the subcommand's parser, which names
        it, not by the main one (``bearingsim run x.toml --bogus``: ``bearingsim run: error: ...``); a negative
        value given apart from its option (``--step -10%``) is the option's value, which the option then judges
        (argparse read ``-10%`` as an unknown option and said only "expected one argument")."""
        args = _negative_values_joined(sys.argv[1:] if args is None else list(args))
        namespace, extras = self.parse_known_args(args, namespace)
        if extras:
            self._used_parser(namespace).error(f"unrecognized arguments: {' '.join(extras)}")
        return namespace

    def _used_parser(self, namespace) -> argparse.ArgumentParser:
        """The subcommand's parser that read ``namespace``, or this one."""
        for action in self._actions:
            if isinstance(action, argparse._SubParsersAction):
                chosen = action.choices.get(getattr(namespace, action.dest, None))
                if chosen is not None:
                    return chosen._used_parser(namespace) if isinstance(chosen, Parser) else chosen
        return self

    def _check_value(self, action, value):
        try:
            super()._check_value(action, value)
        except argparse.ArgumentError as exc:
            close = difflib.get_close_matches(str(value), [str(c) for c in action.choices or ()], n=1)
            if not close:
                raise
            raise argparse.ArgumentError(action, f"{exc.message}; did you mean {close[0]!r}?") from None


def output_path(text: str) -> str:
    """``-o``'s value: refused when empty (``-o "$OUT"`` with ``OUT`` unset wrote a sweep's files into the
    current folder); ``.`` names the current folder."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path: give a file or folder ('.' for the current one)")
    return text


@contextlib.contextmanager
def options_named(*keywords: str):
    """Within it, a library refusal that starts with one of its ``keywords`` ("rotations 3:4: outside ...",
    "hours 'x': must be ...") names the command line's option instead ("--rotations 3:4: ..."): the library
    names its keywords, the user gave options."""
    try:
        yield
    except UserError as exc:
        if any(str(exc).startswith(k + " ") for k in keywords):
            raise UserError(f"--{exc}") from None
        raise


def report_study(outcome, command: str) -> int:
    """The end of a study command: exit 0, 1 if a case failed (named on stderr), 128 + signal if
    interrupted (finished cases kept: the same command resumes)."""
    n = max(len(outcome.sweep.rows), outcome.planned)  # a staged study's later cases: not known yet, not run
    if outcome.interrupted is not None:
        ran = sum(outcome.count(s) for s in ("done", "cached", "stale", "failed"))
        print(f"bearingsim: {command} interrupted ({signal.Signals(outcome.interrupted).name}): {outcome.counts()}, "
              f"{n - ran} not run, of {counted(n, 'case')}; run the same command again to resume",
              file=sys.stderr)
        return 128 + outcome.interrupted
    if outcome.failed:
        names = "; ".join(f"{', '.join(f'{k}={v}' for k, v in r['values'].items())}: {r['error']}"
                          for r in outcome.failed[:10])
        rest = n - len(outcome.sweep.rows)  # a staged study stops at a failed case
        later = f"; {counted(rest, 'later case')} not run (each needs the one before)" if rest else ""
        print(f"bearingsim: {len(outcome.failed)} of {counted(n, 'case')} of the {command} failed ({names}); the "
              f"other cases' numbers are kept (errors in {outcome.sweep.csv}){later}", file=sys.stderr)
        return 1
    return 0


def with_notes(rows, what: str, where: str) -> str:
    """The end of a sweep's or study's closing line counting its ``rows`` (the case index's) with notes,
    ``"; 1 case with notes ('bearingsim table DIR' marks them in its notes column and lists them)"``; "" for none.
    ``what``: what a row is (case, rung); ``where``: the path whose table lists them."""
    noted = sum(bool(r.get("notes")) for r in rows)
    return (f"; {counted(noted, what)} with notes ('bearingsim table {where}' marks them in its notes column and "
            f"lists them)" if noted else "")


def progress_wanted(args) -> bool:
    """A progress bar on stderr: only on a terminal, and not with -q."""
    return not getattr(args, "quiet", False) and sys.stderr.isatty()


def say(args):
    """``print``, or with ``-q`` (``args.quiet``) a function that prints nothing: what a command says on success."""
    if getattr(args, "quiet", False):
        return lambda *a, **kw: None
    return print


def given_once(sets, key: str, option: str, value, from_set, what: str):
    """A study's option that a ``--set KEY`` of its scenario may give instead (``crosscheck --speeds`` and
    ``--rotations``, ``life --rotations``): ``value`` (the option's, None when not given), else ``from_set``
    (the scenario's value, when one of ``sets``, the command line's overrides, sets ``key``), else None (the
    study's default). Both given and different is one line naming both (``option``: the option as given;
    ``what``: what is given twice): a ``--set`` the option silently replaced ran, and was stored, unread."""
    from bearingsim.scenario import parse_override

    in_set = key in [parse_override(o)[0] for o in sets]
    if value is not None and in_set and value != from_set:
        shown = from_set[0] if isinstance(from_set, tuple) and len(from_set) == 1 else from_set
        raise UserError(f"{option} and --set {key}={shown:g}: {what} given twice; give one")
    return value if value is not None else (from_set if in_set else None)
