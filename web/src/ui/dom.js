// Small DOM helpers shared by the shell and the panels.

export const byId = (id) => document.getElementById(id);

// One element from an HTML string (a panel's markup, a single root element).
export function fromHtml(html) {
  const template = document.createElement('template');
  template.innerHTML = html.trim();
  return template.content.firstElementChild;
}

// Lookup by id inside a subtree (works before the subtree is in the document).
export function finder(root) {
  return (id) => root.querySelector(`#${id}`);
}
