"""The benchmark suite's report (bench/report): JSON in, Markdown and SVG out."""
