// MathJax 3 (loaded next, in mkdocs.yml's extra_javascript) reads the maths of both kinds of page:
// the Markdown pages, whose maths pymdownx.arithmatex hands over as \( \) and \[ \], and the
// tutorials' notebook pages, whose Markdown cells keep Jupyter's $ $ and $$ $$.
window.MathJax = {
  tex: {
    inlineMath: [["\\(", "\\)"], ["$", "$"]],
    displayMath: [["\\[", "\\]"], ["$$", "$$"]],
    processEscapes: true,
    processEnvironments: true,
  },
};
