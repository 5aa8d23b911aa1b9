"""Reports: the fit reports (Markdown, JSON) and the text and rich summaries the commands print."""
