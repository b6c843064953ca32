// The API token: `costar serve` prints the editor's address with #token=...; the page keeps
// it for the browser tab (sessionStorage) and removes it from the address bar.

const KEY = 'costar-token';

/** The token in the address's fragment (#token=...), kept and removed from the address bar. */
export function tokenFromHash(): string {
  const match = /(?:^#|&)token=([^&]+)/.exec(location.hash);
  if (!match) return '';
  const token = decodeURIComponent(match[1]).trim();
  sessionStorage.setItem(KEY, token);
  history.replaceState(null, '', location.pathname + location.search);
  return token;
}

export function readToken(): string {
  return tokenFromHash() || (sessionStorage.getItem(KEY) ?? '');
}

export function storeToken(token: string) {
  sessionStorage.setItem(KEY, token);
}
