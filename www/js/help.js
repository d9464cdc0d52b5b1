// The Help dialog (#help in index.html): opened by the top bar's Help button or the key ?
// (outside text fields), closed by its Close button, Escape (the native modal <dialog>) or a
// click on the backdrop; the focus returns to where it was.

import { $ } from './dom.js';

/** True when key presses go to a text field (a ? typed there is text, not a command). */
const typing = (el) => !!el && (el.isContentEditable || ['INPUT', 'TEXTAREA', 'SELECT'].includes(el.tagName));

/** Wires the dialog; returns {open, close, isOpen} (the page's hook window.help). */
export function attachHelp() {
  const dialog = $('help');
  const button = $('help-open');
  let opener = null;
  const open = () => {
    if (dialog.open) return;
    opener = document.activeElement;
    dialog.showModal();
    button.setAttribute('aria-expanded', 'true');
    $('help-close').focus();
  };
  const close = () => {
    if (dialog.open) dialog.close();
  };
  button.setAttribute('aria-expanded', 'false');
  button.addEventListener('click', open);
  $('help-close').addEventListener('click', close);
  dialog.addEventListener('close', () => {
    button.setAttribute('aria-expanded', 'false');
    const back = opener && opener.isConnected && opener !== document.body ? opener : button;
    opener = null;
    back.focus();
  });
  // A click on the backdrop (outside the dialog's box) closes it.
  dialog.addEventListener('click', (ev) => {
    if (ev.target !== dialog) return;
    const r = dialog.getBoundingClientRect();
    if (ev.clientX < r.left || ev.clientX > r.right || ev.clientY < r.top || ev.clientY > r.bottom) close();
  });
  document.addEventListener('keydown', (ev) => {
    if (ev.key !== '?' || ev.ctrlKey || ev.metaKey || ev.altKey || typing(ev.target) || dialog.open) return;
    ev.preventDefault();
    open();
  });
  return { open, close, isOpen: () => dialog.open };
}
