"""Sphinx extension: the gallery's index as a grid of thumbnails, each the first figure of its
page as the build drew it.

The gallery's pages are executed at every build, so their figures exist only then. While the
pages are read, the first image of each ``gallery/<page>`` is noted (its source in the
environment, :data:`ENV_KEY`); the ``rockjit-gallery`` directive on the index lists the pages
and is filled in once every page has been read: a link per page holding that image and the
page's title. The HTML builder copies the images as it does for the pages themselves.
"""

from __future__ import annotations

import copy

from docutils import nodes
from docutils.parsers.rst import Directive

#: Where the first image of each gallery page is kept in the build environment.
ENV_KEY = "rockjit_gallery_thumbs"


class gallery_grid(nodes.General, nodes.Element):
    """Placeholder for the grid, filled in at ``doctree-resolved``."""


class GalleryDirective(Directive):
    """``rockjit-gallery``: one line per page of the gallery (docnames relative to the
    index's folder)."""

    has_content = True

    def run(self):
        node = gallery_grid()
        node["pages"] = [line.strip() for line in self.content if line.strip()]
        return [node]


def _note_first_image(app, doctree):
    docname = app.env.docname
    if not docname.startswith("gallery/") or docname == "gallery/index":
        return
    image = next(iter(doctree.findall(nodes.image)), None)
    thumbs = getattr(app.env, ENV_KEY, {})
    if image is not None:
        thumbs[docname] = dict(uri=image["uri"], candidates=dict(image.get("candidates", {})))
    setattr(app.env, ENV_KEY, thumbs)


def _purge(app, env, docname):
    getattr(env, ENV_KEY, {}).pop(docname, None)


def _merge(app, env, docnames, other):
    mine = getattr(env, ENV_KEY, {})
    mine.update({d: v for d, v in getattr(other, ENV_KEY, {}).items() if d in docnames})
    setattr(env, ENV_KEY, mine)


def _fill(app, doctree, docname):
    thumbs = getattr(app.env, ENV_KEY, {})
    folder = docname.rsplit("/", 1)[0] + "/" if "/" in docname else ""
    for grid in list(doctree.findall(gallery_grid)):
        box = nodes.container(classes=["rockjit-gallery"])
        for page in grid["pages"]:
            target = folder + page
            title = app.env.titles.get(target)
            link = nodes.reference("", "", internal=True,
                                   refuri=app.builder.get_relative_uri(docname, target))
            thumb = thumbs.get(target)
            if thumb is not None:
                image = nodes.image(uri=thumb["uri"], alt=title.astext() if title else page)
                image["candidates"] = copy.deepcopy(thumb["candidates"])
                link += image
            link += nodes.inline(text=title.astext() if title else page)
            box += nodes.paragraph("", "", link)
        grid.replace_self(box)


def setup(app):
    app.add_node(gallery_grid)
    app.add_directive("rockjit-gallery", GalleryDirective)
    app.connect("doctree-read", _note_first_image)
    app.connect("env-purge-doc", _purge)
    app.connect("env-merge-info", _merge)
    app.connect("doctree-resolved", _fill)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True,
            "env_version": 1}
