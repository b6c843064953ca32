// The API token: `costar serve` prints the editor's address with #token=...; the page keeps
// it for the browser tab (sessionStorage) and removes it from the address bar.

const KEY = 'costar-token';

export function readToken(): string {
  const match = /(?:^#|&)token=([^&]+)/.exec(location.hash);
  if (match) {
    const token = decodeURIComponent(match[1]);
    sessionStorage.setItem(KEY, token);
    history.replaceState(null, '', location.pathname + location.search);
    return token;
  }
  return sessionStorage.getItem(KEY) ?? '';
}

export function storeToken(token: string) {
  sessionStorage.setItem(KEY, token);
}
