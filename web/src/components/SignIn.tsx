// The sign-in box: shown over the page when the token is missing or the server refused it.
// The token is what `costar serve` printed (in the address it prints, or its --token-file).

import { useState } from 'react';

interface Props {
  problem: 'missing' | 'wrong';
  onToken: (token: string) => void;
  onDismiss: () => void;
}

export function SignIn({ problem, onToken, onDismiss }: Props) {
  const [text, setText] = useState('');
  const submit = () => {
    // Accept the whole address too: take what follows #token=.
    const match = /token=([^&\s]+)/.exec(text);
    const token = (match ? decodeURIComponent(match[1]) : text).trim();
    if (token) onToken(token);
  };
  return (
    <div className="overlay" role="dialog" aria-label="Sign in">
      <form
        className="signin"
        onSubmit={(e) => {
          e.preventDefault();
          submit();
        }}
      >
        <h2>Sign in to the robot</h2>
        <p className={problem === 'wrong' ? 'reason' : ''}>
          {problem === 'wrong'
            ? 'The server refused this token. Paste the token (or the whole address) that costar serve printed.'
            : 'Sign in to change plans or move the robot: open the address costar serve printed, or paste its token (or the whole address) here.'}
        </p>
        <input
          aria-label="token"
          autoFocus
          placeholder="token, or http://…/#token=…"
          value={text}
          onChange={(e) => setText(e.target.value)}
        />
        <div className="signin-buttons">
          <button type="submit" className="primary">
            Sign in
          </button>
          <button type="button" onClick={onDismiss}>
            Look only
          </button>
        </div>
        <p className="dim">The token is in the terminal where the server started (“open the editor at …#token=…”).</p>
      </form>
    </div>
  );
}
