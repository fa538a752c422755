;;; lensc.el --- .lens job files and lensc's language server in Emacs -*- lexical-binding: t -*-

;; A `lens-mode' for `.lens' files (`//' and `/* */' comments, keywords
;; highlighted) and eglot set up to run `lensc lsp' (which must be on
;; PATH) in it.  Works with the eglot built into Emacs 29 and later, and
;; on Emacs 28 with eglot from ELPA (Debian 12: the elpa-eglot package).
;; Load it from your init file:
;;
;;   (load "/path/to/lensc/editors/emacs/lensc.el")
;;
;; then M-x eglot in a .lens buffer, or add `eglot-ensure' to
;; `lens-mode-hook' as below.  Tested headless on Debian 12's Emacs 28.2
;; (tests/it/editors.rs).

;;; Code:

(require 'eglot)

(defvar lens-mode-syntax-table
  (let ((table (make-syntax-table)))
    ;; `//' line comments and `/* */' block comments.
    (modify-syntax-entry ?/ ". 124b" table)
    (modify-syntax-entry ?* ". 23" table)
    (modify-syntax-entry ?\n "> b" table)
    (modify-syntax-entry ?_ "_" table)
    table)
  "Syntax table for `lens-mode'.")

(defconst lens-font-lock-keywords
  `((,(regexp-opt '("use" "let" "surface" "tool" "machine" "strategy" "dialect" "job") 'words)
     . font-lock-keyword-face)
    ("\\_<\\([A-Za-z_][A-Za-z0-9_]*\\)\\s-*:" 1 font-lock-variable-name-face))
  "Highlighting for `lens-mode': item keywords and parameter names.")

;;;###autoload
(define-derived-mode lens-mode prog-mode "lens"
  "Major mode for lensc's `.lens' lens-machining job files."
  (setq-local comment-start "// ")
  (setq-local comment-end "")
  (setq-local font-lock-defaults '(lens-font-lock-keywords)))

;;;###autoload
(add-to-list 'auto-mode-alist '("\\.lens\\'" . lens-mode))
(add-to-list 'eglot-server-programs '(lens-mode "lensc" "lsp"))
(add-hook 'lens-mode-hook #'eglot-ensure)

(provide 'lensc)
;;; lensc.el ends here
