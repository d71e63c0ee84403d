// backlash/symbolic/document.hpp — a small document model rendered both as
// Markdown (math that renders on GitHub and GitLab: inline $`…`$, display
// ```math blocks) and as LaTeX (for report.pdf), so every page is written once.
//
// Text spans are plain text (escaped for each target, see escape.hpp), inline
// math (LaTeX, passed through), inline code, bold text or links.  Display
// equations are LaTeX bodies (pretty::display gives aligned blocks with
// \tag{N} for the thesis's equation numbers).
#pragma once

#include <string>
#include <vector>

namespace backlash::symbolic::doc {

struct Span {
  enum class Kind { Text, Math, Code, Bold, Link };
  Kind kind = Kind::Text;
  std::string text;
  std::string target;  ///< Link: a relative path (Markdown) — LaTeX prints the text only
};
using Rich = std::vector<Span>;

Rich text(std::string s);
Rich math(std::string latex);
Rich code(std::string s);
Rich bold(std::string s);
Rich link(std::string s, std::string target);
Rich operator+(Rich a, const Rich& b);

struct Block {
  enum class Kind { Heading, Paragraph, Equation, Table, Figure, Code, List };
  Kind kind = Kind::Paragraph;
  int level = 1;                          ///< Heading
  Rich content;                           ///< Heading, Paragraph
  std::string anchor;                     ///< Heading: LaTeX \label
  std::string equation;                   ///< Equation: LaTeX body (may hold \tag{…})
  std::vector<Rich> header;               ///< Table
  std::vector<std::vector<Rich>> rows;    ///< Table
  std::string align;                      ///< Table: one of l, r, c per column
  bool small = false;                     ///< Table: set in a smaller font in LaTeX
  std::string latex_columns;              ///< Table: LaTeX column spec (e.g. "lp{6cm}"); default from `align`
  std::string figure;                     ///< Figure: path without extension, relative to the report root
  Rich caption;                           ///< Figure, Table
  std::string language, source;           ///< Code
  std::vector<Rich> items;                ///< List
};
using Document = std::vector<Block>;

Block heading(int level, Rich content, std::string anchor = "");
Block paragraph(Rich content);
Block equation(std::string latex);
Block table(std::vector<Rich> header, std::vector<std::vector<Rich>> rows, std::string align = "", Rich caption = {});
Block figure(std::string path_without_extension, Rich caption);
Block code_block(std::string language, std::string source);
Block list(std::vector<Rich> items);

struct MarkdownOptions {
  std::string root;                 ///< prefix from the page to the report root ("../" for cases/V.md)
  std::string figure_extension = ".svg";
};
std::string to_markdown(const Document& document, const MarkdownOptions& options = {});

struct LatexOptions {
  std::string figure_extension = ".pdf";
  int top_level = 1;  ///< heading level 1 → \section (2 → \subsection …); shifted by top_level − 1
};
std::string to_latex(const Document& document, const LatexOptions& options = {});

}  // namespace backlash::symbolic::doc
