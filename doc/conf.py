# Sphinx configuration of the GRANULAR-CHARGED manual.
#
# Build (warnings are errors):
#   /usr/bin/python3 -m sphinx -W --keep-going -b html doc build/doc-html
# or scripts/check_manual.sh, which also checks every local link and that every page and
# example is reachable from the index.  Debian's python3-sphinx, python3-myst-parser and
# python3-sphinx-rtd-theme are enough (scripts/install-deps.sh installs them).

project = "GRANULAR-CHARGED"
author = "GRANULAR-CHARGED developers"
copyright = "GRANULAR-CHARGED developers"

extensions = ["myst_parser"]

# The style pages in LAMMPS's format are to become reStructuredText (LAMMPS's doc/src);
# the guide and the other pages are Markdown read by myst-parser.
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"

# Not pages of the manual: the kept runs and their notes (doc/data), the figures' folder
# (images are included by the pages that show them), and doc/README.md, the short pointer
# to this manual that a reader of the repository sees on its own.
exclude_patterns = ["data", "figures", "README.md", "_build", "Thumbs.db", ".DS_Store"]

# Markdown: plain CommonMark plus tables; the pages write their equations as text, so no
# "$...$" maths (a shell variable such as ${zlo} must stay text). Anchors for "#section"
# links inside a page and between pages (headings down to level 4).
myst_enable_extensions = []
myst_heading_anchors = 4

html_theme = "sphinx_rtd_theme"
html_title = "GRANULAR-CHARGED manual"
html_show_sourcelink = False
html_theme_options = {"navigation_depth": 3, "collapse_navigation": False}

# Local links only: the build machine has no internet access, and the manual's
# external references (papers, LAMMPS's own manual) are not ours to keep alive.
# scripts/check_manual.sh runs "-b linkcheck" with these ignored.
linkcheck_ignore = [r"https?://.*", r"mailto:.*"]
linkcheck_anchors = True


# Links from a page to a file or folder of the repository that is not a page (the kept
# runs in doc/data, a figure's folder, an example deck, a source file) resolve to that path
# in the checkout, relative to the built HTML, so that they work when the manual is opened
# from build/doc-html.  A path that does not exist is left alone and warns as before.
import os

_DOC_DIR = os.path.dirname(os.path.abspath(__file__))
_REPO_DIR = os.path.dirname(_DOC_DIR)


def _repository_path(app, env, node, contnode):
    from docutils import nodes

    target = node.get("reftarget", "")
    if not target or "://" in target or target.startswith(("#", "mailto:")):
        return None
    path, _, anchor = target.partition("#")
    refdoc = node.get("refdoc", env.docname)
    source = os.path.normpath(os.path.join(_DOC_DIR, os.path.dirname(refdoc), path))
    if not source.startswith(_REPO_DIR + os.sep) or not os.path.exists(source):
        return None
    docname = os.path.splitext(os.path.relpath(source, _DOC_DIR))[0].replace(os.sep, "/")
    if docname in env.found_docs:
        return None  # a page of the manual: an unresolved link to it (bad anchor) must warn
    if app.builder.name == "linkcheck":
        # Sphinx's linkcheck tests a local link as a path relative to the page's source.
        uri = os.path.relpath(source, os.path.join(_DOC_DIR, os.path.dirname(refdoc)))
        uri = uri.replace(os.sep, "/")
    else:
        page_dir = os.path.join(app.outdir, os.path.dirname(refdoc))
        uri = os.path.relpath(source, page_dir).replace(os.sep, "/")
    if os.path.isdir(source):
        uri += "/"
    if anchor:
        uri += "#" + anchor
    ref = nodes.reference("", "", internal=False, refuri=uri)
    ref += contnode
    return ref


# The style pages link LAMMPS's own pages as LAMMPS's doc/src does (:doc:`fix <fix>`), so that
# they can be copied there unchanged.  In this manual those links go to LAMMPS's online manual;
# only the names listed here do, so that a mistyped link to one of our own pages still warns.
LAMMPS_PAGES = {
    "atom_style", "comm_modify", "compute", "compute_pair_local", "compute_reduce",
    "compute_coord_atom", "compute_rdf", "create_atoms", "dump", "fix", "fix_deposit",
    "fix_freeze", "fix_modify", "fix_move", "fix_neigh_history", "fix_nve_sphere", "fix_pour",
    "fix_rigid", "fix_wall_gran", "fix_wall_gran_region", "kspace_style", "minimize",
    "neigh_modify", "neighbor", "newton", "package", "pair_coeff", "pair_granular",
    "pair_style", "processors", "read_restart", "restart", "run", "run_style", "suffix",
    "thermo_style", "units", "variable", "write_restart", "Build_package", "Speed_opt",
    "fix_efield", "fix_scafacos", "balance", "Howto_output", "compute_contact_atom",
    "compute_fabric", "kspace_modify", "pair_coul", "dielectric", "pair_modify", "compute_voronoi_atom", "pair_hybrid", "fix_ave_time", "set", "displace_atoms",
}


def _lammps_page(app, env, node, contnode):
    if node.get("reftype") != "doc":
        return None
    target = node.get("reftarget", "")
    if target not in LAMMPS_PAGES:
        return None
    from docutils import nodes

    ref = nodes.reference("", "", internal=False, refuri=f"https://docs.lammps.org/{target}.html")
    ref += contnode
    return ref


# LAMMPS's doc/src writes input lines as ".. code-block:: LAMMPS"; Pygments has no lexer of
# that name, so a small one here: comments, variables, numbers, the command word of a line.
def _lammps_lexer():
    from pygments.lexer import RegexLexer, bygroups
    from pygments.token import Comment, Keyword, Name, Number, Punctuation, String, Text

    class LAMMPSLexer(RegexLexer):
        name = "LAMMPS"
        aliases = ["lammps"]
        tokens = {
            "root": [
                (r"#.*?$", Comment),
                (r"^(\s*)([a-z_]+)", bygroups(Text, Keyword)),
                (r"\$\{[^}]*\}|\$[A-Za-z]|v_\w+|[cf]_\w+(\[[0-9*]+\])?", Name.Variable),
                (r'"[^"]*"', String),
                (r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?\b", Number),
                (r"&\s*$", Punctuation),
                (r"\s+", Text),
                (r"\S+?", Text),
            ]
        }

    return LAMMPSLexer


def setup(app):
    app.add_lexer("LAMMPS", _lammps_lexer())
    app.connect("missing-reference", _repository_path)
    app.connect("missing-reference", _lammps_page)
