"""The command line's parser as the manual shows it (doc/cli.rst, through sphinx-argparse).

sphinx-argparse reads descriptions and help texts as reStructuredText, where a lone "*" (as in
"Ad*" or "figures/*.png") starts emphasis; the texts are plain text written for a terminal, so
every markup character of reStructuredText is escaped here.  The parser is the one the command
uses, granular_charged.cli.build_parser(); nothing else is changed.
"""
import argparse
import re

from granular_charged.cli import build_parser

_RST_SPECIAL = re.compile(r"([*`|_\\])")


def _escape(text):
    return _RST_SPECIAL.sub(r"\\\1", text) if text else text


def _escape_parser(parser, done):
    # argparse's parents= lets several parsers hold one action object: each object is
    # escaped once
    if id(parser) in done:
        return
    done.add(id(parser))
    parser.description = _escape(parser.description)
    parser.epilog = _escape(parser.epilog)
    for action in parser._actions:
        if id(action) not in done and action.help not in (None, argparse.SUPPRESS):
            done.add(id(action))
            action.help = _escape(action.help)
        if isinstance(action, argparse._SubParsersAction):
            for choice in action._choices_actions:
                if id(choice) not in done:
                    done.add(id(choice))
                    choice.help = _escape(choice.help)
            for sub in action.choices.values():
                _escape_parser(sub, done)


def parser_for_manual():
    parser = build_parser()
    _escape_parser(parser, set())
    return parser
